// The Vulkan backend on its own: heaps, bindless slots (persistent, double-buffered, freed to
// null), the shader assert channel, debug names.
#include "gpu_test_env.h"

#include <cstring>
#include <unistd.h>

#include "common/shared_types.h"
#include "rhi/frame.h"
#include "rhi/pipeline.h"
#include "rhi/shader_messages.h"

using namespace shadel;
using namespace shadel::test;

namespace {

struct Probe {
    Gpu& gpu = sharedGpu();
    Pipeline pipeline = createComputePipeline(gpu, "test.probe", "tests_probe.comp.spv");
    BufferHandle constants = createBuffer(
        gpu, {"test.frameConstants", sizeof(gpu::FrameConstants), 0, MemoryKind::Upload});
    BufferHandle result = createBuffer(gpu, {"test.result", 16, 0, MemoryKind::Readback});
    ShaderMessageChannel messages;
    FrameRecorder recorder;
    Probe() {
        initShaderMessages(gpu, messages);
        initFrameRecorder(gpu, recorder, TimingMode::Timestamps);
        gpu::FrameConstants f{};
        f.messages = shaderMessagesAddress(gpu, messages);
        std::memcpy(mapped(gpu, constants), &f, sizeof(f));
    }
    ~Probe() {
        destroyFrameRecorder(recorder);
        destroyShaderMessages(gpu, messages);
        destroy(gpu, constants);
        destroy(gpu, result);
        destroy(gpu, pipeline);
    }
    // Runs one frame reading `slot`; returns texel (0,0) as seen by the shader.
    glm::vec4 read(uint32_t slot, bool raiseAssert = false) {
        beginFrame(recorder);
        pass(recorder, "probe", [&](VkCommandBuffer cmd) {
            struct {
                uint64_t frame, result;
                uint32_t slot, raise;
            } push{address(gpu, constants), address(gpu, result), slot, raiseAssert ? 1u : 0u};
            bind(gpu, cmd, pipeline);
            pushConstants(gpu, cmd, push);
            vkCmdDispatch(cmd, 1, 1, 1);
            memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                          VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                          VK_ACCESS_2_HOST_READ_BIT);
        });
        endFrame(recorder);
        glm::vec4 v;
        std::memcpy(&v, mapped(gpu, result), 16);
        return v;
    }
};

TextureHandle solidTexture(Gpu& gpu, uint8_t r, uint8_t g, uint8_t b) {
    TextureDesc d;
    d.name = "test.solid";
    d.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
    TextureHandle t = createTexture(gpu, d);
    uint8_t px[4] = {r, g, b, 255};
    uploadTexture(gpu, t, px, 4);
    return t;
}

} // namespace

TEST(Bindless, ShadersReachTexturesBySlotAndFreedSlotsReadNull) {
    Probe probe;
    Gpu& gpu = probe.gpu;
    uint32_t before = validationErrors();
    TextureHandle red = solidTexture(gpu, 255, 0, 0);
    TextureReadView view = createReadView(gpu, red);
    uint32_t s = slot(gpu, view).value;
    glm::vec4 v = probe.read(s);
    EXPECT_NEAR(v.r, 1.0f, 1e-3);
    EXPECT_NEAR(v.g, 0.0f, 1e-3);
    // Two frames later (both sets updated) the same slot still holds the view: persistent.
    probe.read(s);
    EXPECT_NEAR(probe.read(s).r, 1.0f, 1e-3);

    destroy(gpu, view);
    destroy(gpu, red);
    // The freed slot is not handed out again until both sets hold the null resource...
    TextureHandle green = solidTexture(gpu, 0, 255, 0);
    TextureReadView other = createReadView(gpu, green);
    EXPECT_NE(slot(gpu, other).value, s);
    // ...and reads as the null (black) resource.
    for (int i = 0; i < 2; ++i) {
        glm::vec4 n = probe.read(s);
        EXPECT_EQ(n, glm::vec4(0, 0, 0, 0)) << "frame " << i;
    }
    EXPECT_NEAR(probe.read(slot(gpu, other).value).g, 1.0f, 1e-3);
    // After both sets were refreshed, the slot is reusable.
    TextureHandle blue = solidTexture(gpu, 0, 0, 255);
    TextureReadView third = createReadView(gpu, blue);
    EXPECT_EQ(slot(gpu, third).value, s);
    EXPECT_NEAR(probe.read(s).b, 1.0f, 1e-3);
    destroy(gpu, other);
    destroy(gpu, green);
    destroy(gpu, third);
    destroy(gpu, blue);
    EXPECT_EQ(validationErrors(), before);
}

TEST(ShaderMessages, AssertsAreReportedOnceWithLocationAndCounted) {
    Probe probe;
    probe.read(0, false);
    EXPECT_EQ(collectShaderMessages(probe.gpu, probe.messages), 0u);
    probe.read(7, true);
    EXPECT_EQ(collectShaderMessages(probe.gpu, probe.messages), 1u);
    probe.read(7, true);
    EXPECT_EQ(collectShaderMessages(probe.gpu, probe.messages), 1u);
    EXPECT_EQ(probe.messages.totalAsserts, 2u);
    ASSERT_EQ(probe.messages.lines.size(), 1u) << "a repeated assert is printed once";
    const std::string& line = probe.messages.lines[0];
    EXPECT_NE(line.find("test assert"), std::string::npos) << line;
    EXPECT_NE(line.find("shaders/tests/probe.comp:"), std::string::npos) << line;
    EXPECT_NE(line.find("values 42 7"), std::string::npos) << line;
}

TEST(Memory, HeapsSubAllocateFromPoolsAndFailureIsAValue) {
    Gpu& gpu = sharedGpu();
    MemoryHeapStats before = memoryStats(gpu.memory);
    std::vector<BufferHandle> buffers;
    for (int i = 0; i < 8; ++i) buffers.push_back(createBuffer(gpu, {"test.small", 4096}));
    MemoryHeapStats during = memoryStats(gpu.memory);
    EXPECT_EQ(during.allocations, before.allocations + 8);
    EXPECT_LE(during.pools, before.pools + 1) << "small buffers share a pool";
    for (BufferHandle b : buffers) destroy(gpu, b);
    EXPECT_EQ(memoryStats(gpu.memory).allocations, before.allocations);
    // Larger than the whole pool limit: an invalid handle, not an abort.
    BufferHandle huge =
        createBuffer(gpu, {"test.huge", gpu.memory.poolSize * (gpu.memory.maxPoolsPerHeap + 1)});
    EXPECT_FALSE(huge.valid());
}

// The device's pipeline library (rhi/pipeline.h): the same request answers with the pipeline
// already built; a different name, specialization or state builds another; destroy() gives the
// caller's use back while the pipeline stays usable for the others.
TEST(PipelineLibrary, TheSameRequestSharesOnePipelineAndAnyDifferenceBuildsAnother) {
    Gpu& gpu = sharedGpu();
    // A name no other test uses, so the first request below always compiles.
    const std::string name = "test.library." + std::to_string(::getpid());
    PipelineLibraryCounters before = pipelineLibraryCounters(gpu);
    Pipeline a = createComputePipeline(gpu, name, "tests_probe.comp.spv");
    PipelineLibraryCounters afterFirst = pipelineLibraryCounters(gpu);
    EXPECT_EQ(afterFirst.created, before.created + 1);
    EXPECT_GT(afterFirst.createSeconds, before.createSeconds);
    Pipeline again = createComputePipeline(gpu, name, "tests_probe.comp.spv");
    EXPECT_EQ(again.pipeline, a.pipeline);
    EXPECT_EQ(pipelineLibraryCounters(gpu).shared, afterFirst.shared + 1);
    EXPECT_EQ(pipelineLibraryCounters(gpu).created, afterFirst.created);

    Pipeline specialized = createComputePipeline(gpu, name, "tests_probe.comp.spv", {{0, 1}});
    Pipeline renamed = createComputePipeline(gpu, name + ".other", "tests_probe.comp.spv");
    EXPECT_NE(specialized.pipeline, a.pipeline);
    EXPECT_NE(renamed.pipeline, a.pipeline);
    EXPECT_EQ(pipelineLibraryCounters(gpu).created, afterFirst.created + 2);

    GraphicsPipelineDesc d;
    d.name = name + ".depth";
    d.vertexShader = "forward_forward.vert.spv";
    d.depthFormat = VK_FORMAT_D32_SFLOAT;
    Pipeline depth = createGraphicsPipeline(gpu, d);
    d.depthCompare = VK_COMPARE_OP_EQUAL; // state is part of the key
    Pipeline equal = createGraphicsPipeline(gpu, d);
    EXPECT_NE(equal.pipeline, depth.pipeline);
    d.depthCompare = VK_COMPARE_OP_GREATER_OR_EQUAL;
    Pipeline depthAgain = createGraphicsPipeline(gpu, d);
    EXPECT_EQ(depthAgain.pipeline, depth.pipeline);
    EXPECT_EQ(pipelineLibraryCounters(gpu).created, afterFirst.created + 4);

    destroy(gpu, again); // the caller's use only: `a` still runs (validation would flag it)
    EXPECT_EQ(again.pipeline, VK_NULL_HANDLE);
    EXPECT_EQ(createComputePipeline(gpu, name, "tests_probe.comp.spv").pipeline, a.pipeline);
    uint32_t errors = validationErrors();
    Probe probe;
    destroy(gpu, probe.pipeline);
    probe.pipeline = a;
    TextureHandle red = solidTexture(gpu, 255, 0, 0);
    TextureReadView view = createReadView(gpu, red);
    EXPECT_NEAR(probe.read(slot(gpu, view).value).r, 1.0f, 1e-3);
    EXPECT_EQ(validationErrors(), errors);
    destroy(gpu, view);
    destroy(gpu, red);
    for (Pipeline* p : {&specialized, &renamed, &depth, &equal, &depthAgain}) destroy(gpu, *p);
}

// Renderers created one after another on one device (the bench's modes, a test's runs) compile
// each pipeline once: the second run of the same options builds none and draws the same bytes.
TEST(PipelineLibrary, ASecondRunOfTheSameOptionsCompilesNothing) {
    RenderOptions o = renderOptions("builtin:default", RenderMode::Decoupled, 128, 72);
    o.frames = 2;
    RenderRun first = renderChecked(o);
    RenderRun second = renderChecked(o);
    const nlohmann::json &a = first.stats["pipelines"], &b = second.stats["pipelines"];
    EXPECT_GT(a["created"].get<uint64_t>() + a["shared"].get<uint64_t>(), 10u);
    EXPECT_EQ(b["created"].get<uint64_t>(), 0u);
    EXPECT_EQ(b["shared"].get<uint64_t>(),
              a["created"].get<uint64_t>() + a["shared"].get<uint64_t>());
    EXPECT_EQ(b["create_ms"].get<double>(), 0.0);
    ASSERT_EQ(first.frames.size(), second.frames.size());
    for (size_t f = 0; f < first.frames.size(); ++f)
        EXPECT_EQ(first.frames[f].rgba, second.frames[f].rgba) << "frame " << f;
}

// A batch compiles what the library lacks side by side and answers the rest from it; the same
// request twice in one batch is one pipeline.
TEST(PipelineLibrary, ABatchCompilesOnlyWhatTheLibraryLacks) {
    Gpu& gpu = sharedGpu();
    const std::string name = "test.batch." + std::to_string(::getpid());
    uint32_t errors = validationErrors();
    Pipeline known = createComputePipeline(gpu, name + ".known", "tests_probe.comp.spv");
    PipelineLibraryCounters before = pipelineLibraryCounters(gpu);
    std::vector<Pipeline> batch =
        createComputePipelines(gpu, {{name + ".known", "tests_probe.comp.spv", {}},
                                     {name + ".a", "tests_probe.comp.spv", {}},
                                     {name + ".b", "tests_probe.comp.spv", {{0, 7}}},
                                     {name + ".a", "tests_probe.comp.spv", {}}});
    ASSERT_EQ(batch.size(), 4u);
    EXPECT_EQ(batch[0].pipeline, known.pipeline);
    EXPECT_EQ(batch[3].pipeline, batch[1].pipeline);
    EXPECT_NE(batch[1].pipeline, batch[2].pipeline);
    for (const Pipeline& p : batch) {
        EXPECT_NE(p.pipeline, VK_NULL_HANDLE);
        EXPECT_EQ(p.bindPoint, VK_PIPELINE_BIND_POINT_COMPUTE);
    }
    EXPECT_EQ(batch[2].name, name + ".b");
    PipelineLibraryCounters after = pipelineLibraryCounters(gpu);
    EXPECT_EQ(after.shared, before.shared + 1);
    // .a twice in one batch: both compiled side by side, the library keeps the first.
    EXPECT_EQ(after.created, before.created + 3);
    // A stage that does not exist is one clear error, and nothing of the batch leaks.
    EXPECT_THROW(createComputePipelines(gpu, {{name + ".c", "tests_probe.comp.spv", {}},
                                              {name + ".d", "no_such_stage.comp.spv", {}}}),
                 DeviceError);
    EXPECT_EQ(validationErrors(), errors);
    destroy(gpu, known);
    for (Pipeline& p : batch) destroy(gpu, p);
}
