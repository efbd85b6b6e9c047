// Block-compressed textures (bake/block_compression, --texture-compression): the device's BC
// decoder (lavapipe samples BC images) against the CPU decoder the quality figures use, on random
// BC7 blocks of every mode and on encoded images; then textured sample models streamed as BC7 and
// as RGBA8, each compared with the glTF Sample Viewer's image, with the memory per texel the
// stats report.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "bake/block_compression/block_compression.h"
#include "conformance_oracle.h"
#include "rhi/frame.h"
#include "rhi/pipeline.h"
#include "scene_files.h"

using namespace shadel;
using namespace shadel::test;
namespace fs = std::filesystem;

namespace {

// Every texel of level 0 of a bindless slot as the device fetches it.
struct TexelProbe {
    Gpu& gpu = sharedGpu();
    Pipeline pipeline = createComputePipeline(gpu, "test.texelProbe", "tests_texel_probe.comp.spv");
    FrameRecorder recorder;
    TexelProbe() { initFrameRecorder(gpu, recorder, TimingMode::Timestamps); }
    ~TexelProbe() {
        destroyFrameRecorder(recorder);
        destroy(gpu, pipeline);
    }
    std::vector<float> read(uint32_t slot, uint32_t w, uint32_t h) {
        BufferHandle result =
            createBuffer(gpu, {"test.texels", uint64_t(w) * h * 16, 0, MemoryKind::Readback});
        beginFrame(recorder);
        pass(recorder, "texelProbe", [&](VkCommandBuffer cmd) {
            struct {
                uint64_t result;
                uint32_t slot, width, height;
            } push{address(gpu, result), slot, w, h};
            bind(gpu, cmd, pipeline);
            pushConstants(gpu, cmd, push);
            vkCmdDispatch(cmd, (w + 7) / 8, (h + 7) / 8, 1);
            memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                          VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                          VK_ACCESS_2_HOST_READ_BIT);
        });
        endFrame(recorder);
        std::vector<float> out(size_t(w) * h * 4);
        std::memcpy(out.data(), mapped(gpu, result), out.size() * sizeof(float));
        destroy(gpu, result);
        return out;
    }
};

VkFormat vkFormatOf(BlockFormat f) {
    return f == BlockFormat::Bc7   ? VK_FORMAT_BC7_UNORM_BLOCK
           : f == BlockFormat::Bc5 ? VK_FORMAT_BC5_UNORM_BLOCK
                                   : VK_FORMAT_BC4_UNORM_BLOCK;
}

// The largest difference, in 8-bit steps, between the device's decode of `blocks` and the CPU's.
int largestDecodeDifference(TexelProbe& probe, BlockFormat format,
                            const std::vector<uint8_t>& blocks, uint32_t w, uint32_t h) {
    Gpu& gpu = probe.gpu;
    TextureDesc d;
    d.name = std::string("test.") + blockFormatName(format);
    d.format = vkFormatOf(format);
    d.width = w, d.height = h;
    TextureHandle t = createTexture(gpu, d);
    uploadTexture(gpu, t, blocks.data(), blocks.size());
    TextureReadView view = createReadView(gpu, t);
    std::vector<float> device = probe.read(slot(gpu, view).value, w, h);
    std::vector<uint8_t> cpu = decodeImage(format, blocks.data(), w, h);
    int largest = 0;
    for (size_t i = 0; i < cpu.size(); ++i)
        largest = std::max(largest, std::abs(int(std::lround(device[i] * 255.0f)) - int(cpu[i])));
    destroy(gpu, view);
    destroy(gpu, t);
    return largest;
}

std::vector<uint8_t> smoothImage(uint32_t w, uint32_t h) {
    std::vector<uint8_t> out(size_t(w) * h * 4);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            uint8_t* p = &out[(size_t(y) * w + x) * 4];
            p[0] = uint8_t(255 * x / (w - 1));
            p[1] = uint8_t(x + y > w ? 210 : 40);
            p[2] = uint8_t(255 * y / (h - 1));
            p[3] = uint8_t((x * 7 + y * 3) % 256);
        }
    return out;
}

} // namespace

TEST(TextureCompressionGpu, DeviceDecodesAsTheCpuDecoder) {
    TexelProbe probe;
    SHADEL_REQUIRE(probe.gpu.device.optional.textureCompressionBC,
                   "textureCompressionBC on the device");
    uint32_t before = validationErrors();
    const uint32_t w = 64, h = 64;
    // Random blocks: every BC7 mode (the first byte's lowest set bit is the mode; never 0, the
    // reserved mode), every partition, rotation and index selection.
    std::mt19937 rng(7);
    std::vector<uint8_t> random(size_t(w / 4) * (h / 4) * 16);
    for (uint8_t& b : random) b = uint8_t(rng());
    for (size_t i = 0; i < random.size(); i += 16)
        if (random[i] == 0) random[i] = uint8_t(1u << (i / 16 % 8));
    EXPECT_EQ(largestDecodeDifference(probe, BlockFormat::Bc7, random, w, h), 0)
        << "random BC7 blocks of every mode";
    std::vector<uint8_t> image = smoothImage(w, h);
    for (BlockFormat f : {BlockFormat::Bc7, BlockFormat::Bc5, BlockFormat::Bc4}) {
        std::vector<uint8_t> blocks = encodeImage(f, image.data(), w, h);
        int d = largestDecodeDifference(probe, f, blocks, w, h);
        std::printf("[ figures ] %s: device and CPU decodes differ by at most %d steps\n",
                    blockFormatName(f), d);
        // BC4/BC5 interpolate in more than 8 bits on the device: one step of rounding.
        EXPECT_LE(d, f == BlockFormat::Bc7 ? 0 : 1) << blockFormatName(f);
    }
    EXPECT_EQ(validationErrors(), before);
}

// Textured sample models streamed (every texture through the layered cache) as BC7 and as RGBA8,
// each against the Sample Viewer's image: BC7 keeps the image's PSNR within a fraction of a dB of
// RGBA8's, at a quarter of the memory per texel.
TEST(TextureCompressionRender, StreamedModelsAgainstTheSampleViewer) {
    Gpu& gpu = sharedGpu();
    SHADEL_REQUIRE(gpu.device.optional.textureCompressionBC, "textureCompressionBC on the device");
    struct Case {
        const char* model;
        double floorBc, floorNone; // measured less 1.5 dB
    } cases[] = {{"BoxTextured", 41.5, 41.4}, {"TextureTransformTest", 51.4, 51.8}};
    for (const Case& c : cases) {
        nlohmann::json model = conformanceModel(c.model);
        ASSERT_FALSE(model.is_null()) << c.model;
        SHADEL_REQUIRE(fs::exists(model["resources"].get<std::string>()),
                       model["resources"].get<std::string>() << " (the assimp-testmodels package)");
        int w = 0, h = 0;
        std::vector<uint8_t> ref = loadConformanceReference(c.model, w, h);
        ASSERT_FALSE(ref.empty()) << c.model;
        fs::path scene = stageConformanceModel(model);
        for (TextureCompression compression : {TextureCompression::Bc, TextureCompression::None}) {
            const bool bc = compression == TextureCompression::Bc;
            RenderOptions o = conformanceOptions(scene.string(), RenderMode::Forward, w, h);
            o.textureBudgetMiB = 64.0; // streamed; every texture fits at full resolution
            o.textureCompression = compression;
            o.frames = 3; // the tails first, the full levels land a frame later
            RenderRun run = renderChecked(o);
            ASSERT_EQ(run.frames.size(), 3u);
            std::vector<uint8_t> img = run.frames.back().rgba;
            compositeOverBlack(img);
            ConformanceMeasure m = measureAgainstReference(ref, img);
            const nlohmann::json& s = run.stats;
            const double perTexel = s["texture_bytes_per_texel"].get<double>();
            std::printf("[ figures ] %s streamed %s: PSNR %.2f dB against the Sample Viewer, "
                        "%.4f bytes per texel, texture_total_bytes %llu, peak %llu\n",
                        c.model, bc ? "bc7" : "rgba8", m.psnr, perTexel,
                        (unsigned long long)s["texture_total_bytes"].get<uint64_t>(),
                        (unsigned long long)s["texture_memory_peak_bytes"].get<uint64_t>());
            EXPECT_EQ(s["texture_streaming"]["compression"], bc ? "bc7" : "rgba8");
            EXPECT_GE(m.psnr, bc ? c.floorBc : c.floorNone)
                << c.model << (bc ? " bc7" : " rgba8") << ": measured " << m.psnr << " dB";
            if (bc) {
                // 1 byte a texel; the 2x2 and 1x1 levels take a whole 16-byte block each.
                EXPECT_GE(perTexel, 1.0);
                EXPECT_LE(perTexel, 1.01) << "measured " << perTexel;
                for (const auto& psnr : s["texture_streaming"]["psnr_db"])
                    EXPECT_GE(psnr.get<double>(), 40.0) << c.model << ": a texture's BC7 PSNR";
            } else {
                EXPECT_DOUBLE_EQ(perTexel, 4.0);
            }
        }
        fs::remove_all(scene.parent_path());
    }
}

// Without device support the file is RGBA8: a warning naming the reason, the reason in the stats,
// 4 bytes a texel; and a bad --texture-compression value is one input error.
TEST(TextureCompressionRender, WithoutDeviceSupportTexturesStreamAsRgba8) {
    const std::string stats = tempPath("texture_compression_fallback.json");
    const std::string args = "render --size 32x18 --scene builtin:textures --gallery-texture-size "
                             "64 --texture-budget 4 --stats " +
                             stats;
    std::string err;
    ASSERT_EQ(runShadel("SHADEL_DISABLE_BC=1", args, err), 0) << err;
    EXPECT_NE(err.find("--texture-compression bc"), std::string::npos) << err;
    std::ifstream in(stats);
    nlohmann::json s = nlohmann::json::parse(in);
    EXPECT_EQ(s["texture_streaming"]["compression"], "rgba8");
    EXPECT_NE(s["texture_streaming"]["compression_fallback"].get<std::string>().find(
                  "textureCompressionBC"),
              std::string::npos);
    EXPECT_DOUBLE_EQ(s["texture_bytes_per_texel"].get<double>(), 4.0);
    EXPECT_EQ(runShadel("", args + " --texture-compression bc9", err), 2);
    EXPECT_NE(err.find("--texture-compression"), std::string::npos) << err;
    fs::remove(stats);
}
