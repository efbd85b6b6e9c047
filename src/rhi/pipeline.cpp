#include "rhi/pipeline.h"

#include <cstdlib>
#include <fstream>

#include "core/log.h"
#include "rhi/gpu.h"
#include "rhi/shader_reload.h"

#ifndef SHADEL_SHADER_BINARY_DIR
#define SHADEL_SHADER_BINARY_DIR "shaders"
#endif

namespace shadel {

std::string shaderDirectory() {
    if (const char* env = std::getenv("SHADEL_SHADER_DIR")) return env;
    return SHADEL_SHADER_BINARY_DIR;
}

std::vector<uint32_t> loadSpirv(const std::string& fileName) {
    std::string path = shaderDirectory() + "/" + fileName;
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) throw DeviceError(format("%s: cannot open compiled shader", path.c_str()));
    std::streamsize bytes = in.tellg();
    if (bytes <= 0 || bytes % 4) throw DeviceError(format("%s: not a SPIR-V file", path.c_str()));
    std::vector<uint32_t> code(size_t(bytes) / 4);
    in.seekg(0);
    in.read(reinterpret_cast<char*>(code.data()), bytes);
    if (code[0] != 0x07230203) throw DeviceError(format("%s: bad SPIR-V magic", path.c_str()));
    return code;
}

static VkShaderModule createModule(Gpu& gpu, const std::string& file) {
    const std::vector<uint32_t>* reloaded = reloadedSpirv(gpu, file); // hot reload's newest
    std::vector<uint32_t> code = reloaded ? *reloaded : loadSpirv(file);
    VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    ci.codeSize = code.size() * 4;
    ci.pCode = code.data();
    VkShaderModule module;
    VK_CHECK(vkCreateShaderModule(gpu.device.device, &ci, nullptr, &module));
    setName(gpu.device, module, VK_OBJECT_TYPE_SHADER_MODULE, file);
    return module;
}

struct Specialization {
    std::vector<VkSpecializationMapEntry> entries;
    std::vector<uint32_t> data;
    VkSpecializationInfo info{};
    explicit Specialization(const std::vector<std::pair<uint32_t, uint32_t>>& constants) {
        for (auto& [id, value] : constants) {
            entries.push_back({id, uint32_t(data.size() * 4), 4});
            data.push_back(value);
        }
        info.mapEntryCount = uint32_t(entries.size());
        info.pMapEntries = entries.data();
        info.dataSize = data.size() * 4;
        info.pData = data.data();
    }
    const VkSpecializationInfo* get() const { return entries.empty() ? nullptr : &info; }
};

Pipeline createGraphicsPipeline(Gpu& gpu, const GraphicsPipelineDesc& desc) {
    Specialization spec(desc.specialization);
    VkShaderModule vs = createModule(gpu, desc.vertexShader);
    VkShaderModule fs =
        desc.fragmentShader.empty() ? VK_NULL_HANDLE : createModule(gpu, desc.fragmentShader);
    VkPipelineShaderStageCreateInfo stages[2]{};
    stages[0] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = vs;
    stages[0].pName = "main";
    stages[0].pSpecializationInfo = spec.get();
    stages[1] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = fs;
    stages[1].pName = "main";
    stages[1].pSpecializationInfo = spec.get();

    VkPipelineVertexInputStateCreateInfo vertexInput{
        VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    VkPipelineInputAssemblyStateCreateInfo assembly{
        VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    assembly.topology = desc.topology;
    VkPipelineViewportStateCreateInfo viewport{
        VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo raster{
        VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = desc.cullMode;
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    raster.depthClampEnable = desc.depthClamp;
    raster.depthBiasEnable = desc.depthBias;
    raster.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo ms{
        VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    VkPipelineDepthStencilStateCreateInfo depth{
        VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    depth.depthTestEnable = desc.depthTest;
    depth.depthWriteEnable = desc.depthWrite;
    depth.depthCompareOp = desc.depthCompare;
    depth.stencilTestEnable = desc.stencilTest;
    depth.front = depth.back = desc.stencil;
    std::vector<VkPipelineColorBlendAttachmentState> blends(desc.colorFormats.size());
    for (auto& b : blends) {
        b.colorWriteMask = 0xF;
        if (desc.blend == GraphicsPipelineDesc::Blend::Alpha) {
            b.blendEnable = VK_TRUE;
            b.srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA;
            b.dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
            b.colorBlendOp = VK_BLEND_OP_ADD;
            b.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
            b.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
            b.alphaBlendOp = VK_BLEND_OP_ADD;
        } else if (desc.blend == GraphicsPipelineDesc::Blend::Additive) {
            b.blendEnable = VK_TRUE;
            b.srcColorBlendFactor = b.dstColorBlendFactor = VK_BLEND_FACTOR_ONE;
            b.srcAlphaBlendFactor = b.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
        }
    }
    if (!desc.attachmentBlends.empty()) {
        if (desc.attachmentBlends.size() != desc.colorFormats.size())
            throw DeviceError(format("pipeline %s: %zu attachment blends for %zu colour targets",
                                     desc.name.c_str(), desc.attachmentBlends.size(),
                                     desc.colorFormats.size()));
        blends = desc.attachmentBlends;
    }
    VkPipelineColorBlendStateCreateInfo blend{
        VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    blend.attachmentCount = uint32_t(blends.size());
    blend.pAttachments = blends.data();
    VkDynamicState dynamics[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR,
                                 VK_DYNAMIC_STATE_DEPTH_BIAS};
    VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic.dynamicStateCount = desc.depthBias ? 3 : 2;
    dynamic.pDynamicStates = dynamics;
    VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
    rendering.colorAttachmentCount = uint32_t(desc.colorFormats.size());
    rendering.pColorAttachmentFormats = desc.colorFormats.data();
    rendering.depthAttachmentFormat = desc.depthFormat;
    if (desc.depthFormat == VK_FORMAT_D32_SFLOAT_S8_UINT ||
        desc.depthFormat == VK_FORMAT_D24_UNORM_S8_UINT)
        rendering.stencilAttachmentFormat = desc.depthFormat;

    VkGraphicsPipelineCreateInfo ci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    ci.pNext = &rendering;
    ci.stageCount = fs ? 2 : 1;
    ci.pStages = stages;
    ci.pVertexInputState = &vertexInput;
    ci.pInputAssemblyState = &assembly;
    ci.pViewportState = &viewport;
    ci.pRasterizationState = &raster;
    ci.pMultisampleState = &ms;
    ci.pDepthStencilState = &depth;
    ci.pColorBlendState = &blend;
    ci.pDynamicState = &dynamic;
    ci.layout = gpu.bindless.pipelineLayout;
    Pipeline out;
    out.name = desc.name;
    out.bindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    VK_CHECK(vkCreateGraphicsPipelines(gpu.device.device, VK_NULL_HANDLE, 1, &ci, nullptr,
                                       &out.pipeline));
    setName(gpu.device, out.pipeline, VK_OBJECT_TYPE_PIPELINE, desc.name);
    vkDestroyShaderModule(gpu.device.device, vs, nullptr);
    if (fs) vkDestroyShaderModule(gpu.device.device, fs, nullptr);
    recordPipeline(gpu, out, &desc, "", desc.specialization);
    return out;
}

Pipeline createComputePipeline(Gpu& gpu, const std::string& name, const std::string& shader,
                               const std::vector<std::pair<uint32_t, uint32_t>>& specialization) {
    Specialization spec(specialization);
    VkShaderModule cs = createModule(gpu, shader);
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = cs;
    ci.stage.pName = "main";
    ci.stage.pSpecializationInfo = spec.get();
    ci.layout = gpu.bindless.pipelineLayout;
    Pipeline out;
    out.name = name;
    out.bindPoint = VK_PIPELINE_BIND_POINT_COMPUTE;
    VK_CHECK(vkCreateComputePipelines(gpu.device.device, VK_NULL_HANDLE, 1, &ci, nullptr,
                                      &out.pipeline));
    setName(gpu.device, out.pipeline, VK_OBJECT_TYPE_PIPELINE, name);
    vkDestroyShaderModule(gpu.device.device, cs, nullptr);
    recordPipeline(gpu, out, nullptr, shader, specialization);
    return out;
}

void destroy(Gpu& gpu, Pipeline& pipeline) {
    forgetPipeline(gpu, pipeline.pipeline); // and its hot-reload replacement
    if (pipeline.pipeline) vkDestroyPipeline(gpu.device.device, pipeline.pipeline, nullptr);
    pipeline.pipeline = VK_NULL_HANDLE;
}

void bind(const Gpu& gpu, VkCommandBuffer cmd, const Pipeline& pipeline) {
    vkCmdBindPipeline(cmd, pipeline.bindPoint, currentPipeline(gpu, pipeline.pipeline));
    VkDescriptorSet set = currentBindlessSet(gpu);
    vkCmdBindDescriptorSets(cmd, pipeline.bindPoint, gpu.bindless.pipelineLayout, 0, 1, &set, 0,
                            nullptr);
}

void pushConstants(const Gpu& gpu, VkCommandBuffer cmd, const void* data, uint32_t size) {
    vkCmdPushConstants(cmd, gpu.bindless.pipelineLayout, VK_SHADER_STAGE_ALL, 0, size, data);
}

} // namespace shadel
