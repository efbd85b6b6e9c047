#include "rhi/pipeline.h"
#include "rhi/pipeline_spirv.h"

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <future>
#include <mutex>
#include <string_view>
#include <thread>
#include <unordered_map>
#include <unordered_set>

#include "core/assert.h"
#include "core/log.h"
#include "rhi/gpu.h"
#include "rhi/pipeline_cache.h"
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

// The SPIR-V a stage is built from: hot reload's newest, else the compiled file.
static std::vector<uint32_t> stageSpirv(const Gpu& gpu, const std::string& file) {
    const std::vector<uint32_t>* reloaded = reloadedSpirv(gpu, file);
    return reloaded ? *reloaded : loadSpirv(file);
}

static VkShaderModule createModule(Gpu& gpu, const std::string& file,
                                   const std::vector<uint32_t>& code) {
    VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    ci.codeSize = code.size() * 4;
    ci.pCode = code.data();
    VkShaderModule module;
    VK_CHECK(vkCreateShaderModule(gpu.device.device, &ci, nullptr, &module));
    setName(gpu.device, module, VK_OBJECT_TYPE_SHADER_MODULE, file);
    return module;
}

struct PipelineLibrary {
    std::mutex mutex;
    std::unordered_map<std::string, VkPipeline> byKey;
    std::unordered_set<VkPipeline> owned;
    PipelineLibraryCounters counters;
    // Given to every vkCreate*Pipelines (rhi/pipeline_cache.h). Internally synchronized (made
    // without VK_PIPELINE_CACHE_CREATE_EXTERNALLY_SYNCHRONIZED_BIT): threads compile into it at
    // once without the mutex.
    PipelineCacheState cache;
};

static VkPipelineCache cacheOf(const Gpu& gpu) {
    return gpu.pipelineLibrary ? gpu.pipelineLibrary->cache.cache : VK_NULL_HANDLE;
}

// A pipeline's identity as bytes: every input vkCreate*Pipelines sees.
struct KeyWriter {
    std::string bytes;
    template <typename T>
    void pod(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes.append(reinterpret_cast<const char*>(&v), sizeof(T));
    }
    void text(const std::string& t) {
        pod(t.size());
        bytes += t;
    }
    void spirv(const std::vector<uint32_t>& code) {
        pod(code.size());
        pod(std::hash<std::string_view>{}(std::string_view(
            reinterpret_cast<const char*>(code.data()), code.size() * sizeof(uint32_t))));
    }
    void specialization(const std::vector<std::pair<uint32_t, uint32_t>>& constants) {
        pod(constants.size());
        for (auto& [id, value] : constants) pod(id), pod(value);
    }
};

#if defined(__GLIBCXX__) && defined(__x86_64__)
// A field added to GraphicsPipelineDesc must be added to graphicsKey too (then update the size).
static_assert(sizeof(GraphicsPipelineDesc) == 232, "GraphicsPipelineDesc changed: see graphicsKey");
#endif

static std::string graphicsKey(const GraphicsPipelineDesc& d, const std::vector<uint32_t>& vs,
                               const std::vector<uint32_t>* fs) {
    KeyWriter k;
    k.text("graphics");
    k.text(d.name);
    k.text(d.vertexShader);
    k.spirv(vs);
    k.text(d.fragmentShader);
    if (fs) k.spirv(*fs);
    k.pod(d.colorFormats.size());
    for (VkFormat f : d.colorFormats) k.pod(f);
    k.pod(d.depthFormat);
    k.pod(d.depthTest), k.pod(d.depthWrite), k.pod(d.depthCompare), k.pod(d.cullMode);
    k.pod(d.topology), k.pod(d.depthClamp), k.pod(d.depthBias), k.pod(d.blend);
    k.pod(d.dynamicCulling);
    k.pod(d.attachmentBlends.size());
    for (const VkPipelineColorBlendAttachmentState& b : d.attachmentBlends) k.pod(b);
    k.specialization(d.specialization);
    k.pod(d.stencilTest);
    k.pod(d.stencil);
    return std::move(k.bytes);
}

static std::string computeKey(const std::string& name, const std::string& shader,
                              const std::vector<uint32_t>& cs,
                              const std::vector<std::pair<uint32_t, uint32_t>>& specialization) {
    KeyWriter k;
    k.text("compute");
    k.text(name);
    k.text(shader);
    k.spirv(cs);
    k.specialization(specialization);
    return std::move(k.bytes);
}

// The library's pipeline for `key`, or null (then build it and call keepPipeline). Null while
// hot reload is on: its pipelines are built per owner.
static VkPipeline sharedPipeline(Gpu& gpu, const std::string& key) {
    if (gpu.hotReload) return VK_NULL_HANDLE;
    SHADEL_ASSERT(gpu.pipelineLibrary, "createGpu makes the pipeline library");
    PipelineLibrary& l = *gpu.pipelineLibrary;
    std::lock_guard lock(l.mutex);
    auto it = l.byKey.find(key);
    if (it == l.byKey.end()) return VK_NULL_HANDLE;
    ++l.counters.shared;
    return it->second;
}

// Counts a pipeline built in `seconds` and, outside hot reload, keeps it for later requests.
// Two threads that built the same pipeline at once keep the first; the second is destroyed.
static VkPipeline keepPipeline(Gpu& gpu, const std::string& key, VkPipeline built, double seconds) {
    SHADEL_ASSERT(gpu.pipelineLibrary, "createGpu makes the pipeline library");
    PipelineLibrary& l = *gpu.pipelineLibrary;
    std::lock_guard lock(l.mutex);
    ++l.counters.created;
    l.counters.createSeconds += seconds;
    if (gpu.hotReload) return built;
    auto [it, inserted] = l.byKey.emplace(key, built);
    if (!inserted) {
        vkDestroyPipeline(gpu.device.device, built, nullptr);
        return it->second;
    }
    l.owned.insert(built);
    return built;
}

void initPipelineLibrary(Gpu& gpu) {
    gpu.pipelineLibrary = std::make_shared<PipelineLibrary>();
    createPipelineCache(gpu.device, gpu.pipelineLibrary->cache, "");
}

void keepPipelineCacheIn(Gpu& gpu, const std::string& folder) {
    SHADEL_ASSERT(gpu.pipelineLibrary, "createGpu makes the pipeline library");
    PipelineLibrary& l = *gpu.pipelineLibrary;
    std::lock_guard lock(l.mutex);
    SHADEL_ASSERT(l.counters.created == 0, "the pipeline cache is chosen before any pipeline");
    destroyPipelineCache(gpu.device, l.cache, false);
    createPipelineCache(gpu.device, l.cache, folder);
}

bool savePipelineCache(Gpu& gpu) {
    if (!gpu.pipelineLibrary) return true;
    PipelineLibrary& l = *gpu.pipelineLibrary;
    std::lock_guard lock(l.mutex);
    return savePipelineCache(gpu.device, l.cache, l.counters.created > 0);
}

PipelineCacheState pipelineCacheState(const Gpu& gpu) {
    if (!gpu.pipelineLibrary) return {};
    std::lock_guard lock(gpu.pipelineLibrary->mutex);
    return gpu.pipelineLibrary->cache;
}

PipelineLibraryCounters pipelineLibraryCounters(const Gpu& gpu) {
    if (!gpu.pipelineLibrary) return {};
    std::lock_guard lock(gpu.pipelineLibrary->mutex);
    return gpu.pipelineLibrary->counters;
}

PipelineLibraryCounters pipelineLibraryCountersSince(const Gpu& gpu,
                                                     const PipelineLibraryCounters& before) {
    PipelineLibraryCounters now = pipelineLibraryCounters(gpu);
    return {now.created - before.created, now.shared - before.shared,
            now.createSeconds - before.createSeconds};
}

void destroyPipelineLibrary(Gpu& gpu) {
    if (!gpu.pipelineLibrary) return;
    PipelineLibrary& l = *gpu.pipelineLibrary;
    destroyPipelineCache(gpu.device, l.cache, l.counters.created > 0); // saved first
    for (VkPipeline p : l.owned) vkDestroyPipeline(gpu.device.device, p, nullptr);
    gpu.pipelineLibrary.reset();
}

static double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
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
    Pipeline out;
    out.name = desc.name;
    out.bindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    std::vector<uint32_t> vsCode = stageSpirv(gpu, desc.vertexShader), fsCode;
    if (!desc.fragmentShader.empty()) fsCode = stageSpirv(gpu, desc.fragmentShader);
    std::string key = graphicsKey(desc, vsCode, desc.fragmentShader.empty() ? nullptr : &fsCode);
    if ((out.pipeline = sharedPipeline(gpu, key))) return out;

    Specialization spec(desc.specialization);
    VkShaderModule vs = createModule(gpu, desc.vertexShader, vsCode);
    VkShaderModule fs = desc.fragmentShader.empty()
                            ? VK_NULL_HANDLE
                            : createModule(gpu, desc.fragmentShader, fsCode);
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
    std::vector<VkDynamicState> dynamics = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    if (desc.depthBias) dynamics.push_back(VK_DYNAMIC_STATE_DEPTH_BIAS);
    if (desc.dynamicCulling) {
        dynamics.push_back(VK_DYNAMIC_STATE_CULL_MODE);
        dynamics.push_back(VK_DYNAMIC_STATE_FRONT_FACE);
    }
    VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic.dynamicStateCount = uint32_t(dynamics.size());
    dynamic.pDynamicStates = dynamics.data();
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
    auto start = std::chrono::steady_clock::now();
    VkPipeline built = VK_NULL_HANDLE;
    VkResult result =
        vkCreateGraphicsPipelines(gpu.device.device, cacheOf(gpu), 1, &ci, nullptr, &built);
    vkDestroyShaderModule(gpu.device.device, vs, nullptr);
    if (fs) vkDestroyShaderModule(gpu.device.device, fs, nullptr);
    VK_CHECK(result);
    setName(gpu.device, built, VK_OBJECT_TYPE_PIPELINE, desc.name);
    out.pipeline = keepPipeline(gpu, key, built, secondsSince(start));
    recordPipeline(gpu, out, &desc, "", desc.specialization);
    return out;
}

Pipeline createComputePipeline(Gpu& gpu, const std::string& name, const std::string& shader,
                               const std::vector<std::pair<uint32_t, uint32_t>>& specialization) {
    return createComputePipelines(gpu, {{name, shader, specialization}}).front();
}

// One compute pipeline compiled (no library or hot-reload bookkeeping: the caller's thread does
// that). Thread-safe: the device's pipeline cache is internally synchronized (PipelineLibrary).
struct BuiltPipeline {
    VkPipeline pipeline = VK_NULL_HANDLE;
    VkResult result = VK_SUCCESS;
    double seconds = 0.0;
};
static BuiltPipeline buildComputePipeline(const Gpu& gpu, const ComputePipelineDesc& desc,
                                          VkShaderModule cs) {
    Specialization spec(desc.specialization);
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = cs;
    ci.stage.pName = "main";
    ci.stage.pSpecializationInfo = spec.get();
    ci.layout = gpu.bindless.pipelineLayout;
    auto start = std::chrono::steady_clock::now();
    BuiltPipeline b;
    b.result =
        vkCreateComputePipelines(gpu.device.device, cacheOf(gpu), 1, &ci, nullptr, &b.pipeline);
    b.seconds = secondsSince(start);
    return b;
}

std::vector<Pipeline> createComputePipelines(Gpu& gpu,
                                             const std::vector<ComputePipelineDesc>& descs) {
    std::vector<Pipeline> out(descs.size());
    std::vector<std::string> keys(descs.size());
    std::vector<size_t> missing; // not in the library: to compile
    std::vector<VkShaderModule> modules(descs.size(), VK_NULL_HANDLE);
    try {
        for (size_t i = 0; i < descs.size(); ++i) {
            out[i].name = descs[i].name;
            out[i].bindPoint = VK_PIPELINE_BIND_POINT_COMPUTE;
            std::vector<uint32_t> code = stageSpirv(gpu, descs[i].shader);
            keys[i] = computeKey(descs[i].name, descs[i].shader, code, descs[i].specialization);
            if ((out[i].pipeline = sharedPipeline(gpu, keys[i]))) continue;
            missing.push_back(i);
            modules[i] = createModule(gpu, descs[i].shader, code);
        }
    } catch (...) { // a missing or malformed .spv: no module outlives the error
        for (VkShaderModule m : modules)
            if (m) vkDestroyShaderModule(gpu.device.device, m, nullptr);
        throw;
    }
    // The driver compiles a pipeline on the calling thread: the missing ones are taken in turn
    // by as many threads as the machine has (this one included), so a batch costs about its
    // largest pipeline or its share of the machine, whichever is more.
    std::vector<BuiltPipeline> built(descs.size());
    std::atomic<size_t> next{0};
    auto work = [&] {
        for (size_t m; (m = next.fetch_add(1)) < missing.size();)
            built[missing[m]] = buildComputePipeline(gpu, descs[missing[m]], modules[missing[m]]);
    };
    size_t threads =
        std::min<size_t>(missing.size(), std::max(1u, std::thread::hardware_concurrency()));
    size_t helpers = threads > 1 ? threads - 1 : 0;
    std::vector<std::future<void>> others;
    for (size_t t = 0; t < helpers; ++t) others.push_back(std::async(std::launch::async, work));
    work();
    for (std::future<void>& f : others) f.get();
    for (size_t i : missing) vkDestroyShaderModule(gpu.device.device, modules[i], nullptr);
    VkResult failed = VK_SUCCESS;
    for (size_t i : missing) {
        if (built[i].result != VK_SUCCESS) {
            failed = built[i].result;
            continue;
        }
        setName(gpu.device, built[i].pipeline, VK_OBJECT_TYPE_PIPELINE, descs[i].name);
        out[i].pipeline = keepPipeline(gpu, keys[i], built[i].pipeline, built[i].seconds);
        recordPipeline(gpu, out[i], nullptr, descs[i].shader, descs[i].specialization);
    }
    if (failed != VK_SUCCESS) {
        for (Pipeline& p : out) destroy(gpu, p);
        VK_CHECK(failed);
    }
    return out;
}

void destroy(Gpu& gpu, Pipeline& pipeline) {
    if (gpu.pipelineLibrary) {
        std::lock_guard lock(gpu.pipelineLibrary->mutex);
        if (gpu.pipelineLibrary->owned.count(pipeline.pipeline)) {
            pipeline.pipeline = VK_NULL_HANDLE; // the device's library keeps it (destroyGpu)
            return;
        }
    }
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

namespace shadel {

Pipeline createComputePipelineFromSpirv(Gpu& gpu, const std::string& name,
                                        const std::vector<uint32_t>& code) {
    Pipeline out;
    out.name = name;
    out.bindPoint = VK_PIPELINE_BIND_POINT_COMPUTE;
    ComputePipelineDesc desc{name, "(run-time SPIR-V) " + name, {}};
    std::string key = computeKey(desc.name, desc.shader, code, desc.specialization);
    if ((out.pipeline = sharedPipeline(gpu, key))) return out;
    VkShaderModule module = createModule(gpu, desc.shader, code);
    BuiltPipeline built = buildComputePipeline(gpu, desc, module);
    vkDestroyShaderModule(gpu.device.device, module, nullptr);
    VK_CHECK(built.result);
    setName(gpu.device, built.pipeline, VK_OBJECT_TYPE_PIPELINE, name);
    out.pipeline = keepPipeline(gpu, key, built.pipeline, built.seconds);
    return out;
}

} // namespace shadel
