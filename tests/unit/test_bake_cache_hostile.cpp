// Bake-cache files that pass the checksum but lie about the mesh (edited, then re-signed), a
// directory where a cache file should be, and an unwritable cache: each is a rebake with one
// warning, never a black image or an exit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "bake/bake.h"
#include "bake/bake_cache.h"
#include "bake/cache_folder.h"
#include "scene/mesh_utils.h"
#include "temp_dir.h"

using namespace shadel;
using shadel::test::TempDir;
namespace fs = std::filesystem;

namespace {

std::vector<uint8_t> readAll(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}
void writeAll(const fs::path& p, const std::vector<uint8_t>& bytes) {
    std::ofstream f(p, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

// File layout (bake_cache.cpp): a 48-byte header whose last field is the payload checksum, then
// the payload: width, height, 5 more u32 counts, mip count, 2 floats, a double, the vertex
// count, then arrays of (u64 count, elements): remap, UVs, indices, one ID map per level.
constexpr size_t kHeaderBytes = 48, kChecksumOffset = 40, kFixedPayloadBytes = 56;

void resign(std::vector<uint8_t>& file) {
    uint64_t checksum = hashBytes(file.data() + kHeaderBytes, file.size() - kHeaderBytes, 0);
    std::memcpy(file.data() + kChecksumOffset, &checksum, 8);
}

// Byte offset of the first ID of MIP level 0 in the file.
size_t idMapsOffset(const BakedMesh& b) {
    return kHeaderBytes + kFixedPayloadBytes + 8 + b.vertexRemap.size() * 4 + 8 +
           b.shadelUv.size() * 8 + 8 + b.indices.size() * 4 + 8;
}

// Applies edit(id) to every ID of every level.
void editIds(std::vector<uint8_t>& file, const BakedMesh& b, uint16_t (*edit)(uint16_t)) {
    size_t at = idMapsOffset(b);
    for (uint32_t k = 0; k < b.mipCount(); ++k) {
        size_t count = size_t(b.levelWidth(k)) * b.levelHeight(k);
        for (size_t i = 0; i < count; ++i) {
            uint16_t id;
            std::memcpy(&id, &file[at + i * 2], 2);
            id = edit(id);
            std::memcpy(&file[at + i * 2], &id, 2);
        }
        at += count * 2 + 8; // the next level's count
    }
}

struct Fixture {
    TempDir dir{"shadel_bake_hostile"};
    Scene scene;
    BakeSettings settings;
    BakeKey key;
    fs::path file;
    BakedMesh reference;
    std::vector<uint8_t> good;

    Fixture() {
        // A long pipe: a non-square shadel rect, so swapping the sides is a real change.
        scene.meshes.push_back(makeCylinder("pipe", 0.2f, 3.0f, 0, 40));
        key = bakeKey(scene.meshes[0], settings);
        file = bakeCachePath(dir.path.string(), key);
        reference = bakeScene(scene, settings, dir.path.string())[0];
        good = readAll(file);
    }

    // The edited, re-signed file is refused by readBakeCache and bakeScene rebakes it.
    void expectRefused(std::vector<uint8_t> edited, const char* what) {
        resign(edited);
        writeAll(file, edited);
        BakedMesh out;
        std::string why;
        EXPECT_FALSE(readBakeCache(file.string(), key, scene.meshes[0], out, &why)) << what;
        EXPECT_NE(why, "missing") << what;
        EXPECT_NE(why, "checksum mismatch") << what << ": the test must re-sign the file";
        BakedMesh rebuilt = bakeScene(scene, settings, dir.path.string())[0];
        EXPECT_FALSE(rebuilt.fromCache) << what;
        EXPECT_EQ(rebuilt.idMaps, reference.idMaps) << what;
    }
};

} // namespace

TEST(BakeCacheHostile, ResignedUneditedFileIsAccepted) {
    Fixture f;
    std::vector<uint8_t> same = f.good;
    resign(same);
    EXPECT_EQ(same, f.good) << "resign() recomputes the real checksum";
    BakedMesh out;
    std::string why;
    EXPECT_TRUE(readBakeCache(f.file.string(), f.key, f.scene.meshes[0], out, &why)) << why;
}

TEST(BakeCacheHostile, SwappedSizesAreRefused) {
    Fixture f;
    ASSERT_NE(f.reference.width, f.reference.height);
    std::vector<uint8_t> swapped = f.good;
    std::swap_ranges(swapped.begin() + kHeaderBytes, swapped.begin() + kHeaderBytes + 4,
                     swapped.begin() + kHeaderBytes + 4);
    f.expectRefused(swapped, "swapped width and height");
}

TEST(BakeCacheHostile, ZeroedAndShiftedIdMapsAreRefused) {
    Fixture f;
    std::vector<uint8_t> zeroed = f.good;
    editIds(zeroed, f.reference, [](uint16_t) { return uint16_t(0); });
    f.expectRefused(zeroed, "zeroed ID maps");
    std::vector<uint8_t> emptied = f.good;
    editIds(emptied, f.reference, [](uint16_t) { return kEmptyShadel; });
    f.expectRefused(emptied, "empty ID maps");
    uint32_t triangles = f.reference.triangleCount;
    static uint32_t count;
    count = triangles;
    std::vector<uint8_t> shifted = f.good;
    editIds(shifted, f.reference,
            [](uint16_t id) { return id == kEmptyShadel ? id : uint16_t((id + 1) % count); });
    f.expectRefused(shifted, "IDs of the neighbouring triangle");
}

// Used to exit 1 with "basic_filebuf::underflow error reading the file: Is a directory".
TEST(BakeCacheHostile, DirectoryInPlaceOfACacheFileIsARebake) {
    Fixture f;
    fs::remove(f.file);
    fs::create_directories(f.file / "in-the-way");
    testing::internal::CaptureStderr();
    std::vector<BakedMesh> out;
    EXPECT_NO_THROW(out = bakeScene(f.scene, f.settings, f.dir.path.string()));
    std::string log = testing::internal::GetCapturedStderr();
    ASSERT_EQ(out.size(), 1u);
    EXPECT_FALSE(out[0].fromCache);
    EXPECT_EQ(out[0].idMaps, f.reference.idMaps);
    EXPECT_NE(log.find("not a regular file; rebaking"), std::string::npos) << log;
}

TEST(BakeCacheHostile, UnwritableCacheWarnsOnceNotPerMesh) {
    TempDir dir("shadel_bake_hostile");
    fs::path blocker = dir.path / "a-file";
    std::ofstream(blocker) << "not a folder";
    Scene scene;
    for (int i = 0; i < 5; ++i)
        scene.meshes.push_back(makeBox("box", {1.0f + float(i), 1, 1}, 0)); // distinct content
    testing::internal::CaptureStderr();
    std::vector<BakedMesh> out = bakeScene(scene, {}, (blocker / "cache").string());
    std::string log = testing::internal::GetCapturedStderr();
    ASSERT_EQ(out.size(), 5u);
    size_t warnings = 0;
    for (size_t at = log.find("bake cache: cannot write"); at != std::string::npos;
         at = log.find("bake cache: cannot write", at + 1))
        ++warnings;
    EXPECT_EQ(warnings, 1u) << log;
    EXPECT_NE(log.find("Not a directory"), std::string::npos) << log;
}

TEST(BakeCacheHostile, DefaultDirIgnoresEmptyAndRelativeXdgCacheHome) {
    struct Env {
        const char* name;
        std::string saved;
        bool had;
        explicit Env(const char* n) : name(n), had(std::getenv(n) != nullptr) {
            if (had) saved = std::getenv(n);
        }
        ~Env() { had ? setenv(name, saved.c_str(), 1) : unsetenv(name); }
    } shadelCache("SHADEL_CACHE_DIR"), xdg("XDG_CACHE_HOME"), home("HOME");
    unsetenv("SHADEL_CACHE_DIR");
    setenv("HOME", "/home/someone", 1);
    setenv("XDG_CACHE_HOME", "", 1);
    EXPECT_EQ(defaultCacheFolder(), "/home/someone/.cache/shadel");
    setenv("XDG_CACHE_HOME", "relative", 1);
    EXPECT_EQ(defaultCacheFolder(), "/home/someone/.cache/shadel");
    setenv("XDG_CACHE_HOME", "/xdg", 1);
    EXPECT_EQ(defaultCacheFolder(), "/xdg/shadel");
    unsetenv("XDG_CACHE_HOME");
    setenv("HOME", "", 1);
    EXPECT_EQ(defaultCacheFolder(), "/tmp/shadel-cache-" + std::to_string(getuid()));
    setenv("SHADEL_CACHE_DIR", "/explicit", 1);
    EXPECT_EQ(defaultCacheFolder(), "/explicit");
}
