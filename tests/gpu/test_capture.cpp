// --capture NAME and --out FILE.exr (render/debug/capture.h, app/capture_output.h): the named
// resources of the frame come out as files whose contents agree with the frame itself.
#include "gpu_test_env.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sys/wait.h>

#include <stb/stb_image.h>

#include "app/exr_file.h"

using namespace shadel;
using namespace shadel::test;

namespace {

std::filesystem::path tempDir(const std::string& name) {
    auto dir = std::filesystem::temp_directory_path() /
               ("shadel-capture-" + name + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

std::vector<float> readExr(const std::filesystem::path& path, uint32_t& w, uint32_t& h) {
    std::ifstream in(path, std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), {});
    return decodeExrRgba(bytes, w, h);
}

std::vector<uint8_t> readPng(const std::filesystem::path& path, int& w, int& h) {
    int channels = 0;
    uint8_t* data = stbi_load(path.string().c_str(), &w, &h, &channels, 4);
    if (!data) return {};
    std::vector<uint8_t> out(data, data + size_t(w) * h * 4);
    stbi_image_free(data);
    return out;
}

// CPU port of shaders/post/tonemap.comp at 1x: exposure 1, ACES fit, sRGB, 8 bits.
uint8_t tonemap(float hdr) {
    float x = std::max(hdr, 0.0f);
    float y = std::clamp((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
    float s = y < 0.0031308f ? y * 12.92f : 1.055f * std::pow(y, 1.0f / 2.4f) - 0.055f;
    return uint8_t(std::clamp(s, 0.0f, 1.0f) * 255.0f + 0.5f);
}

// Largest per-channel difference between the frame's PNG pixels and the tonemapped EXR.
int maxTonemapError(const std::vector<float>& hdr, const std::vector<uint8_t>& rgba) {
    int worst = 0;
    for (size_t i = 0; i < rgba.size() / 4; ++i)
        for (int c = 0; c < 3; ++c)
            worst = std::max(worst, std::abs(int(tonemap(hdr[i * 4 + c])) - int(rgba[i * 4 + c])));
    return worst;
}

std::string runShadel(const std::string& args, int& exitCode) {
    std::string out = (std::filesystem::temp_directory_path() /
                       ("shadel-capture-cli-" + std::to_string(::getpid()) + ".txt"))
                          .string();
    int status = std::system(
        ("timeout 120 " + std::string(SHADEL_BINARY) + " " + args + " >" + out + " 2>&1").c_str());
    exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::ifstream in(out);
    std::string text((std::istreambuf_iterator<char>(in)), {});
    std::filesystem::remove(out);
    return text;
}

} // namespace

// --out frame.exr holds the linear frame: tonemapped on the CPU it is the PNG the same frame
// gives (within one 8-bit step for float rounding).
TEST(Capture, HdrFrameExrTonemapsToTheDisplayedFrame) {
    auto dir = tempDir("exr");
    RenderOptions o = renderOptions("builtin:smooth", RenderMode::Forward, 96, 54);
    o.out = (dir / "frame.exr").string();
    RenderRun run = renderChecked(o);
    uint32_t w = 0, h = 0;
    std::vector<float> hdr = readExr(o.out, w, h);
    ASSERT_EQ(w, 96u);
    ASSERT_EQ(h, 54u);
    EXPECT_FALSE(std::filesystem::exists(dir / "frame.png"));
    int worst = maxTonemapError(hdr, run.frames.back().rgba);
    std::printf("[ figures ] --out frame.exr vs PNG after CPU tonemap: max error %d/255\n", worst);
    EXPECT_LE(worst, 1);
    float brightest = *std::max_element(hdr.begin(), hdr.end());
    EXPECT_GT(brightest, 0.2f); // not an empty or black frame
    std::filesystem::remove_all(dir);
}

// Every resource of a decoupled frame with a visibility buffer, written and checked against
// the frame: the HDR capture tonemaps to the PNG, depth covers exactly the covered pixels, the
// visibility buffer too, and the storage, masks and sheet are not empty.
TEST(Capture, DecoupledFrameResourcesAgreeWithTheFrame) {
    auto dir = tempDir("all");
    RenderOptions o = renderOptions("builtin:smooth", RenderMode::Decoupled, 96, 54);
    o.marking = MarkingMode::Visibility;
    o.shadeStorageSize = 512; // small storage: a quick readback
    o.captureDir = dir.string();
    o.captures = {
        "hdr",       "depth", "shadow", "visibility", "storage.radiance", "storage.material",
        "occupancy", "sheet"};
    RenderRun run = renderChecked(o);
    ASSERT_EQ(run.captureFiles.size(), o.captures.size());
    for (const std::string& f : run.captureFiles) EXPECT_TRUE(std::filesystem::exists(f)) << f;

    uint32_t w = 0, h = 0;
    std::vector<float> hdr = readExr(dir / "hdr.exr", w, h);
    ASSERT_EQ(w, 96u);
    EXPECT_LE(maxTonemapError(hdr, run.frames.back().rgba), 1);

    std::vector<float> depth = readExr(dir / "depth.exr", w, h);
    ASSERT_EQ(w * h, 96u * 54u);
    uint64_t depthCovered = 0;
    for (size_t i = 0; i < size_t(w) * h; ++i) {
        float z = depth[i * 4];
        EXPECT_TRUE(z >= 0.0f && z <= 1.0f);
        depthCovered += z > 0.0f; // reversed Z: the clear value 0 is the far plane
    }
    EXPECT_EQ(depthCovered, run.frames.back().pixelsCovered);
    EXPECT_GT(depthCovered, 0u);

    int pw = 0, ph = 0;
    std::vector<uint8_t> vis = readPng(dir / "visibility.png", pw, ph);
    ASSERT_EQ(pw * ph, 96 * 54);
    uint64_t visCovered = 0;
    for (size_t i = 0; i < vis.size(); i += 4)
        visCovered += (vis[i] | vis[i + 1] | vis[i + 2]) != 0;
    EXPECT_EQ(visCovered, depthCovered); // every pixel with depth has an instance and triangle

    auto nonBlack = [](const std::vector<uint8_t>& rgba) {
        uint64_t n = 0;
        for (size_t i = 0; i < rgba.size(); i += 4) n += (rgba[i] | rgba[i + 1] | rgba[i + 2]) != 0;
        return n;
    };
    std::vector<uint8_t> occupancy = readPng(dir / "occupancy.png", pw, ph);
    EXPECT_EQ(pw, 1024); // one texel per block of the 64k sheet
    uint64_t markedBlocks = nonBlack(occupancy);
    EXPECT_GT(markedBlocks, 0u);
    EXPECT_EQ(markedBlocks, run.stats["marked_blocks"].get<uint64_t>());
    std::vector<uint8_t> sheet = readPng(dir / "sheet.png", pw, ph);
    EXPECT_GE(nonBlack(sheet), markedBlocks); // blocks in use include every marked one
    std::vector<uint8_t> material = readPng(dir / "storage.material.png", pw, ph);
    EXPECT_EQ(pw, 512);
    EXPECT_GT(nonBlack(material), 0u);
    std::vector<float> radiance = readExr(dir / "storage.radiance.exr", w, h);
    EXPECT_EQ(w, 512u);
    EXPECT_GT(*std::max_element(radiance.begin(), radiance.end()), 0.0f);
    std::vector<float> shadow = readExr(dir / "shadow.exr", w, h);
    EXPECT_GT(*std::max_element(shadow.begin(), shadow.end()), 0.0f); // casters drawn
    std::printf("[ figures ] capture: %llu covered px, %llu marked blocks, %llu sheet blocks\n",
                (unsigned long long)depthCovered, (unsigned long long)markedBlocks,
                (unsigned long long)nonBlack(sheet));
    std::filesystem::remove_all(dir);
}

TEST(Capture, ListPrintsTheNamesAndUnknownNamesExitWith2) {
    int code = -1;
    std::string list = runShadel("render --scene builtin:smooth --size 32x18 --capture list", code);
    EXPECT_EQ(code, 0) << list;
    for (const char* name : {"hdr", "depth", "shadow"})
        EXPECT_NE(list.find(name), std::string::npos) << list;
    EXPECT_EQ(list.find("storage.radiance"), std::string::npos); // forward has no storage
    auto dir = tempDir("cli");
    std::string err = runShadel("render --scene builtin:smooth --size 32x18 --capture depth,nope "
                                "--capture-dir " +
                                    dir.string(),
                                code);
    EXPECT_EQ(code, 2) << err;
    EXPECT_NE(err.find("--capture nope"), std::string::npos) << err;
    EXPECT_FALSE(std::filesystem::exists(dir / "depth.exr")); // failed before rendering
    err = runShadel("render --scene builtin:smooth --size 32x18 --capture depth", code);
    EXPECT_EQ(code, 2) << err; // nowhere to write
    std::filesystem::remove_all(dir);
}
