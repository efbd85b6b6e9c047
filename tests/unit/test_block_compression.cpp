// The block codecs (bake/block_compression): BC7, BC4 and BC5 encoded and decoded by the
// decoder written from the format's definition (its agreement with the GPU's decoder is
// TextureCompressionGpu.* in the GPU tests). Edge cases of single blocks, images whose sides are
// not multiples of 4, and the PSNR against RGBA8 of the textures the gallery scenes use: the glTF
// sample textures (assimp-testmodels) and builtin:textures' procedural ones. Floors are the
// measured figures less at most 1.5 dB.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>

#include "bake/block_compression/block_compression.h"
#include "bake/texture_pack.h"
#include "core/worker_pool.h"
#include "scene/builtin_gallery.h"
#include "scene/load.h"
#include "scene/procedural_textures.h"

using namespace shadel;
namespace fs = std::filesystem;

namespace {

std::vector<uint8_t> roundTrip(BlockFormat format, const std::vector<uint8_t>& rgba, uint32_t w,
                               uint32_t h) {
    std::vector<uint8_t> blocks = encodeImage(format, rgba.data(), w, h);
    EXPECT_EQ(blocks.size(), encodedBytes(format, w, h));
    return decodeImage(format, blocks.data(), w, h);
}

double psnrOf(BlockFormat format, const std::vector<uint8_t>& rgba, uint32_t w, uint32_t h) {
    std::vector<uint8_t> decoded = roundTrip(format, rgba, w, h);
    return imagePsnr(rgba.data(), decoded.data(), size_t(w) * h, blockFormatChannels(format));
}

// A smooth colour field (3 steps a texel) with a sharp diagonal edge and a little noise: a
// texture-like image at any size.
std::vector<uint8_t> testImage(uint32_t w, uint32_t h, bool alpha, uint32_t seed = 1) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> noise(-3, 3);
    std::vector<uint8_t> out(size_t(w) * h * 4);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            uint8_t* p = &out[(size_t(y) * w + x) * 4];
            bool edge = x + 2 * y > w;
            int r = int(40 + 3 * (x % 64)), g = edge ? 200 : 60, b = int(30 + 3 * (y % 64));
            p[0] = uint8_t(std::clamp(r + noise(rng), 0, 255));
            p[1] = uint8_t(std::clamp(g + noise(rng), 0, 255));
            p[2] = uint8_t(std::clamp(b + noise(rng), 0, 255));
            p[3] = alpha ? uint8_t(4 * (x % 64)) : 255;
        }
    return out;
}

} // namespace

TEST(BlockCompression, ConstantBlocksAreExact) {
    const uint8_t colours[][4] = {{255, 0, 0, 255},    {100, 101, 50, 255},  {0, 0, 0, 0},
                                  {17, 200, 3, 128},   {255, 255, 255, 255}, {1, 254, 127, 1},
                                  {128, 128, 128, 255}};
    for (const auto& c : colours) {
        std::vector<uint8_t> block;
        for (int i = 0; i < 16; ++i) block.insert(block.end(), c, c + 4);
        for (BlockFormat f : {BlockFormat::Bc7, BlockFormat::Bc4, BlockFormat::Bc5}) {
            std::vector<uint8_t> decoded = roundTrip(f, block, 4, 4);
            EXPECT_EQ(imagePsnr(block.data(), decoded.data(), 16, blockFormatChannels(f)), 99.0)
                << blockFormatName(f) << " colour " << int(c[0]) << "," << int(c[1]) << ","
                << int(c[2]) << "," << int(c[3]);
        }
    }
}

TEST(BlockCompression, TwoColourBlocks) {
    // Two colours in a checker, in halves, and in a diagonal split (a two-subset partition).
    const uint8_t a[4] = {200, 30, 40, 255}, b[4] = {20, 90, 230, 255};
    for (int pattern = 0; pattern < 3; ++pattern) {
        std::vector<uint8_t> block;
        for (int i = 0; i < 16; ++i) {
            int x = i & 3, y = i >> 2;
            bool second = pattern == 0 ? ((x + y) & 1) : pattern == 1 ? x >= 2 : x > y;
            block.insert(block.end(), second ? b : a, (second ? b : a) + 4);
        }
        double psnr = psnrOf(BlockFormat::Bc7, block, 4, 4);
        std::printf("[ figures ] BC7 two-colour block, pattern %d: %.2f dB\n", pattern, psnr);
        EXPECT_GE(psnr, 53.0) << "pattern " << pattern << ": measured " << psnr << " dB";
    }
}

TEST(BlockCompression, AlphaGradientBlocks) {
    // Constant colour, alpha rising across the block; then colour and alpha rising together.
    for (int colourToo = 0; colourToo < 2; ++colourToo) {
        std::vector<uint8_t> block;
        for (int i = 0; i < 16; ++i) {
            uint8_t t = uint8_t(i * 17);
            block.insert(block.end(),
                         {uint8_t(colourToo ? t : 90), 160, uint8_t(colourToo ? 255 - t : 40), t});
        }
        double psnr = psnrOf(BlockFormat::Bc7, block, 4, 4);
        std::printf("[ figures ] BC7 alpha gradient block (colour %s): %.2f dB\n",
                    colourToo ? "rising too" : "constant", psnr);
        EXPECT_GE(psnr, colourToo ? 45.5 : 50.0) << "measured " << psnr << " dB";
    }
}

// Texels past the edge repeat the edge texel: the image decodes as the top-left corner of the
// same image padded so to whole blocks, and keeps its quality.
TEST(BlockCompression, SidesThatAreNotMultiplesOfFour) {
    const uint32_t sides[][2] = {{1, 1}, {2, 2}, {3, 5}, {5, 3}, {7, 9}, {13, 6}, {64, 31}};
    double lowest = 99.0;
    for (const auto& s : sides) {
        std::vector<uint8_t> image = testImage(s[0], s[1], false, s[0] * 31 + s[1]);
        const uint32_t pw = (s[0] + 3) / 4 * 4, ph = (s[1] + 3) / 4 * 4;
        std::vector<uint8_t> padded(size_t(pw) * ph * 4);
        for (uint32_t y = 0; y < ph; ++y)
            for (uint32_t x = 0; x < pw; ++x)
                std::memcpy(
                    &padded[(size_t(y) * pw + x) * 4],
                    &image[(size_t(std::min(y, s[1] - 1)) * s[0] + std::min(x, s[0] - 1)) * 4], 4);
        EXPECT_EQ(encodedBytes(BlockFormat::Bc7, s[0], s[1]),
                  uint64_t((s[0] + 3) / 4) * ((s[1] + 3) / 4) * 16);
        EXPECT_EQ(encodedBytes(BlockFormat::Bc4, s[0], s[1]),
                  uint64_t((s[0] + 3) / 4) * ((s[1] + 3) / 4) * 8);
        for (BlockFormat f : {BlockFormat::Bc7, BlockFormat::Bc5, BlockFormat::Bc4}) {
            std::vector<uint8_t> decoded = roundTrip(f, image, s[0], s[1]);
            std::vector<uint8_t> whole = roundTrip(f, padded, pw, ph);
            for (uint32_t y = 0; y < s[1]; ++y)
                EXPECT_EQ(0, std::memcmp(&decoded[size_t(y) * s[0] * 4], &whole[size_t(y) * pw * 4],
                                         size_t(s[0]) * 4))
                    << blockFormatName(f) << " " << s[0] << "x" << s[1] << " row " << y;
            double psnr = imagePsnr(image.data(), decoded.data(), size_t(s[0]) * s[1],
                                    blockFormatChannels(f));
            EXPECT_GE(psnr, 44.0) << blockFormatName(f) << " " << s[0] << "x" << s[1]
                                  << ": measured " << psnr << " dB";
            lowest = std::min(lowest, psnr);
        }
    }
    std::printf("[ figures ] lowest PSNR over the odd sizes and formats: %.2f dB\n", lowest);
}

TEST(BlockCompression, SmoothImagesAndAlpha) {
    const uint32_t w = 96, h = 64;
    struct Case {
        BlockFormat format;
        bool alpha;
        double floor;
    } cases[] = {{BlockFormat::Bc7, false, 44.5},
                 {BlockFormat::Bc7, true, 40.5},
                 {BlockFormat::Bc5, false, 52.0},
                 {BlockFormat::Bc4, false, 52.0}};
    for (const Case& c : cases) {
        double psnr = psnrOf(c.format, testImage(w, h, c.alpha), w, h);
        std::printf("[ figures ] %s test image%s: %.2f dB\n", blockFormatName(c.format),
                    c.alpha ? " with an alpha ramp" : "", psnr);
        EXPECT_GE(psnr, c.floor) << blockFormatName(c.format) << ": measured " << psnr << " dB";
    }
}

TEST(BlockCompression, ThreadsEncodeTheSameBytes) {
    std::vector<uint8_t> image = testImage(128, 40, true);
    WorkerPool pool(3);
    EXPECT_EQ(encodeImage(BlockFormat::Bc7, image.data(), 128, 40, &pool),
              encodeImage(BlockFormat::Bc7, image.data(), 128, 40, nullptr));
}

// Every texture of the gallery scenes, BC7 against its RGBA8 texels (as the streaming file
// stores it: at its packed side): at least 40 dB each.
TEST(BlockCompression, GalleryTexturesKeepFortyDecibels) {
    const fs::path models = "/usr/share/assimp/models/glTF2";
    std::vector<std::pair<std::string, Scene>> scenes;
    scenes.emplace_back("builtin:textures", makeTextureGallery(256));
    for (const char* file :
         {"BoxTextured-glTF/BoxTextured.gltf", "BoxTexcoords-glTF/boxTexcoords.gltf",
          "ClearCoat-glTF/ClearCoatTest.gltf", "textureTransform/TextureTransformTest.gltf"})
        if (fs::exists(models / file))
            scenes.emplace_back(file, loadScene((models / file).string(), {true}));
    if (scenes.size() == 1)
        std::printf("[ figures ] assimp-testmodels absent: procedural textures only\n");
    WorkerPool pool(2);
    double lowest = 99.0;
    size_t measured = 0;
    for (auto& [name, scene] : scenes)
        for (size_t i = 0; i < scene.textures.size(); ++i) {
            const Texture& t = scene.textures[i];
            uint32_t side = packedTextureSize(t);
            std::vector<uint8_t> texels(size_t(side) * side * 4);
            if (t.procedural.kind != 0) {
                if (i % 16 != 0) continue; // four of the 64 panels (each kind appears)
                generateProceduralTexture(t.procedural, side, texels.data());
            } else {
                texels = t.rgba8; // the file resamples other sides to a square first
            }
            const uint32_t w = t.procedural.kind ? side : t.width,
                           h = t.procedural.kind ? side : t.height;
            std::vector<uint8_t> blocks = encodeImage(BlockFormat::Bc7, texels.data(), w, h, &pool);
            std::vector<uint8_t> decoded = decodeImage(BlockFormat::Bc7, blocks.data(), w, h);
            double psnr = imagePsnr(texels.data(), decoded.data(), size_t(w) * h, 0xF);
            std::printf("[ figures ] BC7 %s texture %zu (%s, %ux%u): %.2f dB\n", name.c_str(), i,
                        t.name.c_str(), w, h, psnr);
            EXPECT_GE(psnr, 40.0) << name << " texture " << i << ": measured " << psnr << " dB";
            lowest = std::min(lowest, psnr);
            ++measured;
        }
    EXPECT_GE(measured, 4u);
    std::printf("[ figures ] BC7 lowest over %zu gallery textures: %.2f dB\n", measured, lowest);
    EXPECT_GE(lowest, 46.5) << "measured " << lowest << " dB (ClearCoatLabels)";
}
