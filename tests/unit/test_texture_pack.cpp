// The texture streaming file (bake/texture_pack.h): round trip of tiled, pre-filtered levels;
// corrupt, truncated, stale and hostile files are rejected with a reason (never read out of
// bounds: the tests run under ASan too) and rebuilt by openOrBuildTexturePack.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <fcntl.h>
#include <unistd.h>

#include "bake/texture_pack.h"
#include "scene/builtin_gallery.h"
#include "scene/procedural_textures.h"
#include "temp_dir.h"

using namespace shadel;
using shadel::test::TempDir;
namespace fs = std::filesystem;

namespace {

Scene smallScene() {
    Scene scene = makeTextureGallery(32);
    scene.textures.resize(3);
    // An image texture that is neither square nor a power of two: resampled to 16x16.
    Texture image;
    image.name = "image";
    image.width = 12, image.height = 5;
    for (uint32_t i = 0; i < 12 * 5; ++i)
        image.rgba8.insert(image.rgba8.end(), {uint8_t(i * 4), 100, 50, 255});
    scene.textures.push_back(image);
    return scene;
}

std::vector<uint8_t> readLevel(const TexturePack& pack, size_t texture, size_t level) {
    int fd = ::open(pack.path.c_str(), O_RDONLY);
    EXPECT_GE(fd, 0);
    const PackedLevel& l = pack.textures[texture].levels[level];
    std::vector<uint8_t> out(l.bytes);
    std::string why;
    EXPECT_TRUE(readPackedLevel(fd, l, out.data(), &why)) << why;
    ::close(fd);
    return out;
}

void flipByte(const std::string& path, uint64_t offset) {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(std::streamoff(offset));
    char c = 0;
    f.read(&c, 1);
    c ^= 0x5a;
    f.seekp(std::streamoff(offset));
    f.write(&c, 1);
}

} // namespace

TEST(TexturePack, RoundTripTiledLevels) {
    TempDir dir("texpack");
    Scene scene = smallScene();
    TexturePack pack = openOrBuildTexturePack(scene, dir.path.string());
    ASSERT_EQ(pack.textures.size(), 4u);
    EXPECT_EQ(pack.textures[0].size, 32u);
    EXPECT_EQ(pack.textures[0].levels.size(), 6u); // 32 .. 1
    EXPECT_TRUE(pack.textures[0].srgb);
    EXPECT_EQ(pack.textures[3].size, 16u);
    // Level 0 of a procedural texture is the generator's output (32 < one tile: row-major).
    std::vector<uint8_t> expected(32 * 32 * 4);
    generateProceduralTexture(scene.textures[0].procedural, 32, expected.data());
    EXPECT_EQ(readLevel(pack, 0, 0), expected);
    // The 1x1 level is the mean colour (in linear light for sRGB): within the range of level 0.
    std::vector<uint8_t> last = readLevel(pack, 0, 5);
    ASSERT_EQ(last.size(), 4u);
    uint8_t lo = 255, hi = 0;
    for (size_t i = 0; i < expected.size(); i += 4)
        lo = std::min(lo, expected[i]), hi = std::max(hi, expected[i]);
    EXPECT_GE(last[0], lo);
    EXPECT_LE(last[0], hi);
    EXPECT_EQ(last[3], 255);
}

TEST(TexturePack, LargeLevelsAreStoredAsTiles) {
    TempDir dir("texpack");
    Scene scene = makeTextureGallery(256);
    scene.textures.resize(1);
    TexturePack pack = openOrBuildTexturePack(scene, dir.path.string());
    std::vector<uint8_t> full(256 * 256 * 4);
    generateProceduralTexture(scene.textures[0].procedural, 256, full.data());
    std::vector<uint8_t> stored = readLevel(pack, 0, 0);
    // Tile (1, 0) starts after tile (0, 0): its first row is texels 128..255 of row 0.
    const size_t tileBytes = size_t(kTexturePackTile) * kTexturePackTile * 4;
    EXPECT_EQ(0, std::memcmp(&stored[tileBytes], &full[128 * 4], 128 * 4));
    // Tile (0, 1), row 3: texels 0..127 of row 131.
    EXPECT_EQ(0,
              std::memcmp(&stored[2 * tileBytes + 3 * 128 * 4], &full[(131 * 256) * 4], 128 * 4));
}

// With block compression every level is BC7 (whole 4x4 blocks, the 2x2 and 1x1 levels one block
// each), tiled as the RGBA8 file is, a separate file (its own key), each texture's PSNR in the
// directory; level 0's tiles decode to the RGBA8 file's texels within that PSNR.
TEST(TexturePack, BlockCompressedLevelsAreBc7Tiles) {
    TempDir dir("texpack");
    Scene scene = makeTextureGallery(256);
    scene.textures.resize(2);
    TexturePack rgba = openOrBuildTexturePack(scene, dir.path.string());
    TexturePack bc = openOrBuildTexturePack(scene, dir.path.string(), TextureCompression::Bc);
    EXPECT_NE(rgba.path, bc.path);
    ASSERT_EQ(bc.textures.size(), 2u);
    for (size_t t = 0; t < 2; ++t) {
        const PackedTexture& p = bc.textures[t];
        EXPECT_EQ(p.format, BlockFormat::Bc7);
        EXPECT_TRUE(p.srgb);
        for (const PackedLevel& l : p.levels)
            EXPECT_EQ(l.bytes, uint64_t(std::max(l.size / 4, 1u)) * std::max(l.size / 4, 1u) * 16);
        // Level 0 in tile order: each 128^2 tile is 32x32 blocks, row-major.
        std::vector<uint8_t> tiles = readLevel(bc, t, 0), texels = readLevel(rgba, t, 0);
        const size_t tileBlocks = 32 * 32, tileTexels = 128 * 128;
        double worst = 99.0;
        for (size_t k = 0; k < 4; ++k) {
            std::vector<uint8_t> decoded =
                decodeImage(BlockFormat::Bc7, &tiles[k * tileBlocks * 16], 128, 128);
            worst = std::min(
                worst, imagePsnr(decoded.data(), &texels[k * tileTexels * 4], tileTexels, 0xF));
        }
        EXPECT_GE(p.psnr, 40.0f);
        EXPECT_NEAR(worst, p.psnr, 1.0) << "a tile against the whole level's PSNR";
    }
}

TEST(TexturePack, CorruptTruncatedStaleAreRejectedAndRebuilt) {
    TempDir dir("texpack");
    Scene scene = smallScene();
    BakeKey key = texturePackKey(scene);
    std::string path = texturePackPath(dir.path.string(), key);
    TexturePack pack = openOrBuildTexturePack(scene, dir.path.string());
    std::string why;
    TexturePack reopened;
    ASSERT_TRUE(openTexturePack(path, key, reopened, &why)) << why;
    const uint64_t size = fs::file_size(path);

    // A flipped texel in the last level's data.
    flipByte(path, pack.textures[3].levels.back().offset);
    EXPECT_FALSE(openTexturePack(path, key, reopened, &why));
    EXPECT_NE(why.find("checksum"), std::string::npos) << why;
    // ... which the read path also catches (a file corrupted after opening).
    {
        int fd = ::open(path.c_str(), O_RDONLY);
        std::vector<uint8_t> dst(pack.textures[3].levels.back().bytes);
        EXPECT_FALSE(readPackedLevel(fd, pack.textures[3].levels.back(), dst.data(), &why));
        ::close(fd);
    }
    pack = openOrBuildTexturePack(scene, dir.path.string()); // rebuilt
    EXPECT_TRUE(openTexturePack(path, key, reopened, &why)) << why;

    // A flipped byte in the directory.
    flipByte(path, 64 + 3);
    EXPECT_FALSE(openTexturePack(path, key, reopened, &why));
    EXPECT_NE(why.find("directory"), std::string::npos) << why;
    openOrBuildTexturePack(scene, dir.path.string());

    // Truncated at every few bytes of the header + directory, and inside the data.
    for (uint64_t cut : {uint64_t(0), uint64_t(10), uint64_t(63), uint64_t(64), uint64_t(100),
                         size / 2, size - 1}) {
        openOrBuildTexturePack(scene, dir.path.string());
        fs::resize_file(path, cut);
        EXPECT_FALSE(openTexturePack(path, key, reopened, &why)) << cut;
    }
    // Grown.
    openOrBuildTexturePack(scene, dir.path.string());
    fs::resize_file(path, size + 4);
    EXPECT_FALSE(openTexturePack(path, key, reopened, &why));
    pack = openOrBuildTexturePack(scene, dir.path.string());
    EXPECT_EQ(fs::file_size(path), size);

    // Stale: another version number in the header, or the scene's textures changed.
    flipByte(path, 8);
    EXPECT_FALSE(openTexturePack(path, key, reopened, &why));
    EXPECT_NE(why.find("stale"), std::string::npos) << why;
    openOrBuildTexturePack(scene, dir.path.string());
    Scene changed = scene;
    changed.textures[1].procedural.seed += 1;
    BakeKey changedKey = texturePackKey(changed);
    EXPECT_FALSE(changedKey == key);
    EXPECT_FALSE(openTexturePack(path, changedKey, reopened, &why)); // same path, other key
    EXPECT_NE(why.find("key"), std::string::npos) << why;
}

TEST(TexturePack, EveryByteFlipOfTheHeadAndDirectoryIsCaught) {
    TempDir dir("texpack");
    Scene scene = makeTextureGallery(16);
    scene.textures.resize(2);
    BakeKey key = texturePackKey(scene);
    std::string path = texturePackPath(dir.path.string(), key);
    openOrBuildTexturePack(scene, dir.path.string());
    std::ifstream in(path, std::ios::binary);
    std::vector<char> original((std::istreambuf_iterator<char>(in)),
                               std::istreambuf_iterator<char>());
    TexturePack pack;
    ASSERT_TRUE(openTexturePack(path, key, pack, nullptr));
    uint64_t dataStart = pack.textures[0].levels[0].offset;
    for (uint64_t at = 0; at < dataStart; ++at) {
        flipByte(path, at);
        std::string why;
        TexturePack out;
        // Bytes the reader does not interpret (padding) may flip harmlessly; none may pass
        // with a changed meaning, so a pass must give the original directory.
        if (openTexturePack(path, key, out, &why)) {
            ASSERT_EQ(out.textures.size(), pack.textures.size()) << at;
            for (size_t t = 0; t < out.textures.size(); ++t)
                ASSERT_EQ(out.textures[t].levels.size(), pack.textures[t].levels.size()) << at;
        }
        flipByte(path, at); // restore
    }
}

// Without a cache folder, or with one that cannot be written, the pack is built in memory and
// streams the same texels: texture streaming degrades to "run from memory", never fails.
TEST(TexturePack, WithoutAWritableCacheThePackIsBuiltInMemory) {
    TempDir dir("texpack");
    Scene scene = makeTextureGallery(16);
    scene.textures.resize(3);
    TexturePack onDisk = openOrBuildTexturePack(scene, dir.path.string());
    ASSERT_GE(onDisk.fd, 0);
    std::ofstream(dir.path / "a-file") << "not a folder";
    for (const std::string& cacheDir : {std::string(), (dir.path / "a-file" / "cache").string()}) {
        TexturePack inMemory = openOrBuildTexturePack(scene, cacheDir);
        ASSERT_GE(inMemory.fd, 0) << cacheDir;
        EXPECT_EQ(inMemory.path, "(memory)") << cacheDir;
        ASSERT_EQ(inMemory.textures.size(), onDisk.textures.size());
        for (size_t t = 0; t < onDisk.textures.size(); ++t)
            for (size_t l = 0; l < onDisk.textures[t].levels.size(); ++l) {
                const PackedLevel& level = onDisk.textures[t].levels[l];
                std::vector<uint8_t> a(level.bytes), b(level.bytes);
                std::string why;
                ASSERT_TRUE(readPackedLevel(onDisk.fd, level, a.data(), &why)) << why;
                ASSERT_TRUE(
                    readPackedLevel(inMemory.fd, inMemory.textures[t].levels[l], b.data(), &why))
                    << why;
                EXPECT_EQ(a, b) << "texture " << t << " level " << l;
            }
        ::close(inMemory.fd);
    }
    ::close(onDisk.fd);
}
