// The on-disk bake cache and bakeScene: round trip, corruption / truncation / staleness are
// detected and rebuilt, keys separate settings and content, duplicates are baked once, and
// the output does not depend on the thread count.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "bake/bake.h"
#include "bake/bake_cache.h"
#include "scene/mesh_utils.h"
#include "temp_dir.h"

using namespace shadel;
using shadel::test::TempDir;
namespace fs = std::filesystem;

namespace {

Scene twoMeshScene() {
    Scene scene;
    scene.meshes.push_back(makeSphere("ball", 0.5f, 0, 24, 12));
    scene.meshes.push_back(makeBox("crate", {1, 0.5f, 0.7f}, 0));
    scene.meshes.push_back(makeSphere("ball again", 0.5f, 0, 24, 12)); // same content as [0]
    return scene;
}

void expectSameBake(const BakedMesh& a, const BakedMesh& b) {
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.vertexRemap, b.vertexRemap);
    EXPECT_EQ(a.shadelUv, b.shadelUv);
    EXPECT_EQ(a.indices, b.indices);
    EXPECT_EQ(a.idMaps, b.idMaps);
    EXPECT_EQ(a.chartCount, b.chartCount);
    EXPECT_EQ(a.utilisation, b.utilisation);
    EXPECT_EQ(a.shadelsPerMetre, b.shadelsPerMetre);
    EXPECT_EQ(a.forcedTriangles, b.forcedTriangles);
}

std::vector<char> readAll(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}
void writeAll(const fs::path& p, const std::vector<char>& bytes) {
    std::ofstream f(p, std::ios::binary | std::ios::trunc);
    f.write(bytes.data(), std::streamsize(bytes.size()));
}

} // namespace

TEST(BakeCache, RoundTripAndDuplicatesBakedOnce) {
    TempDir dir("shadel_bake_test");
    Scene scene = twoMeshScene();
    BakeSettings settings;
    std::vector<std::pair<size_t, size_t>> calls;
    auto first = bakeScene(scene, settings, dir.path.string(),
                           [&](size_t done, size_t total) { calls.emplace_back(done, total); });
    ASSERT_EQ(first.size(), 3u);
    // Two distinct meshes: progress 0/2, 1/2, 2/2; two cache files.
    ASSERT_EQ(calls.size(), 3u);
    EXPECT_EQ(calls.front(), std::make_pair(size_t(0), size_t(2)));
    EXPECT_EQ(calls.back(), std::make_pair(size_t(2), size_t(2)));
    size_t files = 0;
    for (auto& e : fs::directory_iterator(dir.path)) files += e.path().extension() == ".bin";
    EXPECT_EQ(files, 2u);
    expectSameBake(first[0], first[2]);
    EXPECT_FALSE(first[0].fromCache);

    auto second = bakeScene(scene, settings, dir.path.string());
    for (size_t i = 0; i < 3; ++i) {
        EXPECT_TRUE(second[i].fromCache);
        expectSameBake(first[i], second[i]);
    }
    std::printf("[bake] %s", bakeReport(second, 0.0).c_str());
}

TEST(BakeCache, CorruptedTruncatedAndStaleFilesAreRebuilt) {
    TempDir dir("shadel_bake_test");
    Scene scene;
    scene.meshes.push_back(makeBox("crate", {1, 0.5f, 0.7f}, 0));
    BakeSettings settings;
    BakeKey key = bakeKey(scene.meshes[0], settings);
    fs::path file = bakeCachePath(dir.path.string(), key);
    BakedMesh reference = bakeScene(scene, settings, dir.path.string())[0];
    std::vector<char> good = readAll(file);
    ASSERT_GT(good.size(), 100u);

    auto expectRejectedThenRebuilt = [&](const std::vector<char>& bad, const char* what) {
        writeAll(file, bad);
        BakedMesh out;
        std::string why;
        EXPECT_FALSE(readBakeCache(file.string(), key, scene.meshes[0], out, &why)) << what;
        EXPECT_NE(why, "missing") << what;
        BakedMesh rebuilt = bakeScene(scene, settings, dir.path.string())[0];
        EXPECT_FALSE(rebuilt.fromCache) << what;
        expectSameBake(reference, rebuilt);
        EXPECT_EQ(readAll(file), good) << what << ": the rebuild rewrites the file";
    };

    for (size_t offset : {size_t(3), size_t(20), size_t(60), good.size() / 2, good.size() - 1}) {
        std::vector<char> corrupted = good;
        corrupted[offset] ^= 0x5A;
        expectRejectedThenRebuilt(corrupted, "corrupted byte");
    }
    expectRejectedThenRebuilt(std::vector<char>(good.begin(), good.begin() + good.size() / 3),
                              "truncated");
    expectRejectedThenRebuilt(std::vector<char>(good.begin(), good.begin() + 10),
                              "truncated header");
    expectRejectedThenRebuilt({}, "empty");
    std::vector<char> stale = good;
    stale[8] = char(kBakeFormatVersion + 1); // version field follows the 8-byte magic
    expectRejectedThenRebuilt(stale, "stale version");
    // A file for other content under this key's name (e.g. copied around) is not trusted either.
    Scene other;
    other.meshes.push_back(makeBox("other", {2, 1, 1}, 0));
    BakeKey otherKey = bakeKey(other.meshes[0], settings);
    bakeScene(other, settings, dir.path.string());
    expectRejectedThenRebuilt(readAll(bakeCachePath(dir.path.string(), otherKey)), "foreign file");
}

TEST(BakeCache, KeySeparatesSettingsAndContent) {
    Mesh box = makeBox("crate", {1, 0.5f, 0.7f}, 0);
    BakeSettings settings;
    BakeKey base = bakeKey(box, settings);
    EXPECT_EQ(base, bakeKey(box, settings));
    BakeSettings denser = settings;
    denser.shadelsPerMetre = 64;
    BakeSettings wider = settings;
    wider.gutterShadels = 4;
    BakeSettings smaller = settings;
    smaller.maxResolution = 1024;
    EXPECT_NE(base, bakeKey(box, denser));
    EXPECT_NE(base, bakeKey(box, wider));
    EXPECT_NE(base, bakeKey(box, smaller));
    BakeSettings threads = settings;
    threads.threads = 1; // does not change the output, so not the key
    EXPECT_EQ(base, bakeKey(box, threads));
    Mesh moved = box;
    moved.vertices[0].position.x += 1e-3f;
    EXPECT_NE(base, bakeKey(moved, settings));
    Mesh renormal = box;
    renormal.vertices[0].normal = -renormal.vertices[0].normal;
    EXPECT_NE(base, bakeKey(renormal, settings));
    Mesh reindexed = box;
    std::swap(reindexed.indices[0], reindexed.indices[1]);
    EXPECT_NE(base, bakeKey(reindexed, settings));
    EXPECT_NE(bakeCachePath("/c", base), bakeCachePath("/c", bakeKey(box, denser)));
}

TEST(BakeCache, OutputIndependentOfThreadCount) {
    Scene scene = twoMeshScene();
    scene.meshes.push_back(makeCylinder("pipe", 0.2f, 3.0f, 0, 40));
    BakeSettings one;
    one.threads = 1;
    BakeSettings two;
    two.threads = 2;
    auto a = bakeScene(scene, one, "");
    auto b = bakeScene(scene, two, "");
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) expectSameBake(a[i], b[i]);
}

TEST(BakeCache, UnwritableCacheDirStillBakes) {
    Scene scene;
    scene.meshes.push_back(makeBox("crate", {1, 1, 1}, 0));
    auto out = bakeScene(scene, {}, "/proc/shadel-no-such-dir");
    ASSERT_EQ(out.size(), 1u);
    EXPECT_GT(out[0].width, 0u);
}
