#pragma once
// Pipelines: SPIR-V modules loaded from the build's shader directory, one global pipeline
// layout (the bindless set + 128 bytes of push constants). Vertices are pulled from the
// unified geometry buffer by device address, so no vertex input state is declared.
#include <string>
#include <vector>

#include "rhi/vk.h"

namespace shadel {

struct Gpu;

// Every field is part of the pipeline's key in the device's library (graphicsKey in
// pipeline.cpp, which a static_assert on this struct's size keeps in step).
struct GraphicsPipelineDesc {
    std::string name;
    std::string vertexShader;   // file name of the .spv in the shader directory
    std::string fragmentShader; // empty = depth only
    std::vector<VkFormat> colorFormats;
    VkFormat depthFormat = VK_FORMAT_UNDEFINED;
    bool depthTest = true;
    bool depthWrite = true;
    VkCompareOp depthCompare = VK_COMPARE_OP_GREATER_OR_EQUAL; // reversed Z
    VkCullModeFlags cullMode = VK_CULL_MODE_BACK_BIT;
    VkPrimitiveTopology topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    bool depthClamp = false;
    bool depthBias = false;
    // The cull mode and front face set by the command buffer (vkCmdSetCullMode,
    // vkCmdSetFrontFace) instead of cullMode and counter-clockwise: passes drawing the camera's
    // lists, which cull per list side.
    bool dynamicCulling = false;
    enum class Blend { None, Alpha, Additive } blend = Blend::None;
    // Per colour attachment, overriding `blend` when not empty (e.g. WBOIT's two targets
    // with their separate colour and alpha blending).
    std::vector<VkPipelineColorBlendAttachmentState> attachmentBlends;
    std::vector<std::pair<uint32_t, uint32_t>> specialization; // constant id, value
    // Stencil, for a depthFormat with a stencil aspect (which then is the stencil format too):
    // the test and ops of both faces, with a static reference.
    bool stencilTest = false;
    VkStencilOpState stencil{};
};

struct Pipeline {
    VkPipeline pipeline = VK_NULL_HANDLE;
    VkPipelineBindPoint bindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    std::string name;
};

// Pipelines are kept per device and shared: asking again for a pipeline with the same name,
// SPIR-V, specialization and state returns the one already built instead of compiling it again,
// so renderers created one after another on one device (the bench's modes, scene reloads, a
// test's runs) pay for each pipeline once. destroy() gives the caller's use back; the device
// destroys them (destroyGpu). While shader hot reload is on, every pipeline is built and destroyed
// on its own (the reload swaps pipelines one owner at a time).
struct PipelineLibraryCounters {
    uint64_t created = 0;       // pipelines compiled
    uint64_t shared = 0;        // requests answered with one compiled before
    double createSeconds = 0.0; // spent in vkCreate*Pipelines (summed over threads)
};
void initPipelineLibrary(Gpu& gpu); // createGpu
PipelineLibraryCounters pipelineLibraryCounters(const Gpu& gpu);
// What happened since `before` (an earlier pipelineLibraryCounters): one run's pipelines.
PipelineLibraryCounters pipelineLibraryCountersSince(const Gpu& gpu,
                                                     const PipelineLibraryCounters& before);
void destroyPipelineLibrary(Gpu& gpu); // destroyGpu

std::string shaderDirectory();
std::vector<uint32_t> loadSpirv(const std::string& fileName);
Pipeline createGraphicsPipeline(Gpu& gpu, const GraphicsPipelineDesc& desc);
Pipeline
createComputePipeline(Gpu& gpu, const std::string& name, const std::string& shader,
                      const std::vector<std::pair<uint32_t, uint32_t>>& specialization = {});
struct ComputePipelineDesc {
    std::string name;
    std::string shader; // file name of the .spv in the shader directory
    std::vector<std::pair<uint32_t, uint32_t>> specialization;
};
// Several at once: those not yet in the device's library are compiled in parallel (drivers
// compile on the calling thread; lavapipe takes up to a second for a large shader).
std::vector<Pipeline> createComputePipelines(Gpu& gpu,
                                             const std::vector<ComputePipelineDesc>& descs);
void destroy(Gpu& gpu, Pipeline& pipeline);

// Binds the pipeline and the current bindless set.
void bind(const Gpu& gpu, VkCommandBuffer cmd, const Pipeline& pipeline);
void pushConstants(const Gpu& gpu, VkCommandBuffer cmd, const void* data, uint32_t size);
template <typename T>
void pushConstants(const Gpu& gpu, VkCommandBuffer cmd, const T& value) {
    static_assert(sizeof(T) <= 128, "push constants are limited to 128 bytes");
    pushConstants(gpu, cmd, &value, sizeof(T));
}

} // namespace shadel
