#include "rhi/bindless.h"

#include <algorithm>
#include <string>

#include "core/assert.h"
#include "core/log.h"
#include "rhi/gpu.h"

namespace shadel {

struct SamplerState {
    VkFilter mag = VK_FILTER_LINEAR, min = VK_FILTER_LINEAR;
    VkSamplerMipmapMode mipmap = VK_SAMPLER_MIPMAP_MODE_LINEAR;
    VkSamplerAddressMode u = VK_SAMPLER_ADDRESS_MODE_REPEAT, v = VK_SAMPLER_ADDRESS_MODE_REPEAT;
    float maxLod = VK_LOD_CLAMP_NONE;
    float anisotropy = 1.0f;
    bool compare = false;
};

static VkSampler makeSampler(Gpu& gpu, const SamplerState& st, const std::string& name) {
    VkSamplerCreateInfo ci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    ci.magFilter = st.mag;
    ci.minFilter = st.min;
    ci.mipmapMode = st.mipmap;
    ci.addressModeU = st.u;
    ci.addressModeV = st.v;
    ci.addressModeW = st.u;
    ci.maxLod = st.maxLod;
    ci.anisotropyEnable = st.anisotropy > 1.0f;
    ci.maxAnisotropy = st.anisotropy;
    ci.compareEnable = st.compare;
    ci.compareOp = VK_COMPARE_OP_LESS_OR_EQUAL;
    ci.borderColor = VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE;
    VkSampler s;
    VK_CHECK(vkCreateSampler(gpu.device.device, &ci, nullptr, &s));
    setName(gpu.device, s, VK_OBJECT_TYPE_SAMPLER, name.c_str());
    return s;
}

static SamplerState engineSampler(VkFilter filter, VkSamplerAddressMode mode, float anisotropy,
                                  bool compare) {
    SamplerState st;
    st.mag = st.min = filter;
    st.mipmap =
        filter == VK_FILTER_LINEAR ? VK_SAMPLER_MIPMAP_MODE_LINEAR : VK_SAMPLER_MIPMAP_MODE_NEAREST;
    st.u = st.v = mode;
    st.anisotropy = anisotropy;
    st.compare = compare;
    return st;
}

// The material samplers, in the order of SAMPLER_MATERIAL_* (common/shared_types.h). The
// linearly filtered mipmapped ones filter anisotropically as far as the device allows, up to
// 16x (what the Khronos glTF Sample Viewer asks WebGL for).
static void makeMaterialSamplers(Gpu& gpu, float maxAnisotropy) {
    constexpr VkSamplerAddressMode kWrap[3] = {VK_SAMPLER_ADDRESS_MODE_REPEAT,
                                               VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT,
                                               VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE};
    constexpr const char* kWrapName[3] = {"repeat", "mirror", "clamp"};
    constexpr const char* kMinName[SAMPLER_MIN_COUNT] = {"nearest",           "linear",
                                                         "nearestMipNearest", "linearMipNearest",
                                                         "nearestMipLinear",  "linearMipLinear"};
    float anisotropy = std::min(16.0f, maxAnisotropy);
    uint32_t index = SAMPLER_MATERIAL_FIRST;
    for (uint32_t s = 0; s < 3; ++s)
        for (uint32_t t = 0; t < 3; ++t)
            for (uint32_t mag = 0; mag < 2; ++mag)
                for (uint32_t min = 0; min < SAMPLER_MIN_COUNT; ++min) {
                    SamplerState st;
                    st.u = kWrap[s];
                    st.v = kWrap[t];
                    st.mag = mag == SAMPLER_MAG_LINEAR ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
                    bool linearMin = min == SAMPLER_MIN_LINEAR ||
                                     min == SAMPLER_MIN_LINEAR_MIPMAP_NEAREST ||
                                     min == SAMPLER_MIN_LINEAR_MIPMAP_LINEAR;
                    st.min = linearMin ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
                    st.mipmap = min == SAMPLER_MIN_NEAREST_MIPMAP_LINEAR ||
                                        min == SAMPLER_MIN_LINEAR_MIPMAP_LINEAR
                                    ? VK_SAMPLER_MIPMAP_MODE_LINEAR
                                    : VK_SAMPLER_MIPMAP_MODE_NEAREST;
                    // glTF's NEAREST and LINEAR read level 0 only. A maxLod of 0 would clamp the
                    // level of detail to 0, which selects magFilter; 0.25 keeps minification's
                    // minFilter and still rounds to level 0 (nearest mipmap mode).
                    st.maxLod = min <= SAMPLER_MIN_LINEAR ? 0.25f : VK_LOD_CLAMP_NONE;
                    if (linearMin && min != SAMPLER_MIN_LINEAR) st.anisotropy = anisotropy;
                    std::string name = std::string("sampler.material.") + kWrapName[s] + "." +
                                       kWrapName[t] + "." + (mag ? "linear" : "nearest") + "." +
                                       kMinName[min];
                    gpu.bindless.samplers[index++] = makeSampler(gpu, st, name);
                }
    SHADEL_ASSERT(index == SAMPLER_COUNT);
}

static void writeNow(Gpu& gpu, VkDescriptorSet set, const BindlessWrite& w) {
    BindlessTable& t = gpu.bindless;
    VkDescriptorImageInfo info{};
    if (w.view) {
        info.imageView = w.view;
        info.imageLayout = w.layout;
    } else {
        info.imageView = w.kind == BindlessKind::Sampled ? t.nullSampledView : t.nullStorageView;
        info.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
    }
    VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    write.dstSet = set;
    write.dstBinding = uint32_t(w.kind);
    write.dstArrayElement = w.slot;
    write.descriptorCount = 1;
    write.descriptorType = w.kind == BindlessKind::Sampled ? VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE
                                                           : VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    write.pImageInfo = &info;
    vkUpdateDescriptorSets(gpu.device.device, 1, &write, 0, nullptr);
}

void initBindless(Gpu& gpu) {
    BindlessTable& t = gpu.bindless;
    VkDevice dev = gpu.device.device;
    float maxAniso = gpu.device.properties.limits.maxSamplerAnisotropy;
    float aniso = std::min(8.0f, maxAniso);
    t.samplers[0] = makeSampler(
        gpu, engineSampler(VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT, aniso, false),
        "sampler.linearRepeat");
    t.samplers[1] = makeSampler(
        gpu, engineSampler(VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, 1.0f, false),
        "sampler.linearClamp");
    t.samplers[2] = makeSampler(
        gpu, engineSampler(VK_FILTER_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, 1.0f, false),
        "sampler.nearestClamp");
    t.samplers[3] = makeSampler(
        gpu, engineSampler(VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER, 1.0f, true),
        "sampler.shadowCompare");
    makeMaterialSamplers(gpu, maxAniso);

    VkDescriptorSetLayoutBinding bindings[3]{};
    bindings[0] = {0, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, kBindlessSampledCapacity,
                   VK_SHADER_STAGE_ALL, nullptr};
    bindings[1] = {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, kBindlessStorageCapacity,
                   VK_SHADER_STAGE_ALL, nullptr};
    bindings[2] = {2, VK_DESCRIPTOR_TYPE_SAMPLER, kBindlessSamplerCount, VK_SHADER_STAGE_ALL,
                   t.samplers.data()};
    VkDescriptorBindingFlags flags[3] = {
        VK_DESCRIPTOR_BINDING_PARTIALLY_BOUND_BIT | VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT,
        VK_DESCRIPTOR_BINDING_PARTIALLY_BOUND_BIT | VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT, 0};
    VkDescriptorSetLayoutBindingFlagsCreateInfo flagInfo{
        VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO};
    flagInfo.bindingCount = 3;
    flagInfo.pBindingFlags = flags;
    VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    lci.pNext = &flagInfo;
    lci.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT;
    lci.bindingCount = 3;
    lci.pBindings = bindings;
    VK_CHECK(vkCreateDescriptorSetLayout(dev, &lci, nullptr, &t.layout));
    setName(gpu.device, t.layout, VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, "bindless.layout");

    VkDescriptorPoolSize sizes[3] = {
        {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, 2 * kBindlessSampledCapacity},
        {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 2 * kBindlessStorageCapacity},
        {VK_DESCRIPTOR_TYPE_SAMPLER, 2 * kBindlessSamplerCount}};
    VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pci.flags = VK_DESCRIPTOR_POOL_CREATE_UPDATE_AFTER_BIND_BIT;
    pci.maxSets = 2;
    pci.poolSizeCount = 3;
    pci.pPoolSizes = sizes;
    VK_CHECK(vkCreateDescriptorPool(dev, &pci, nullptr, &t.pool));
    VkDescriptorSetLayout layouts[2] = {t.layout, t.layout};
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = t.pool;
    ai.descriptorSetCount = 2;
    ai.pSetLayouts = layouts;
    VK_CHECK(vkAllocateDescriptorSets(dev, &ai, t.sets.data()));
    setName(gpu.device, t.sets[0], VK_OBJECT_TYPE_DESCRIPTOR_SET, "bindless.set0");
    setName(gpu.device, t.sets[1], VK_OBJECT_TYPE_DESCRIPTOR_SET, "bindless.set1");

    VkPushConstantRange push{VK_SHADER_STAGE_ALL, 0, 128};
    VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    plci.setLayoutCount = 1;
    plci.pSetLayouts = &t.layout;
    plci.pushConstantRangeCount = 1;
    plci.pPushConstantRanges = &push;
    VK_CHECK(vkCreatePipelineLayout(dev, &plci, nullptr, &t.pipelineLayout));
    setName(gpu.device, t.pipelineLayout, VK_OBJECT_TYPE_PIPELINE_LAYOUT,
            "bindless.pipelineLayout");

    // The null resource: 1x1 black, sampled + storage, kept in GENERAL layout.
    TextureDesc nd;
    nd.name = "bindless.null";
    nd.format = VK_FORMAT_R8G8B8A8_UNORM;
    nd.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT;
    t.nullTexture = createTexture(gpu, nd);
    VkImage image = vkImage(gpu, t.nullTexture);
    VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vci.image = image;
    vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vci.format = nd.format;
    vci.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VK_CHECK(vkCreateImageView(dev, &vci, nullptr, &t.nullSampledView));
    t.nullStorageView = t.nullSampledView;
    setName(gpu.device, t.nullSampledView, VK_OBJECT_TYPE_IMAGE_VIEW, "bindless.null.view");
    immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
        imageBarrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_NONE, 0,
                     VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
        VkClearColorValue black{};
        VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        vkCmdClearColorImage(cmd, image, VK_IMAGE_LAYOUT_GENERAL, &black, 1, &range);
        imageBarrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
                     VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_CLEAR_BIT,
                     VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                     VK_ACCESS_2_SHADER_READ_BIT);
    });
    // Every slot of both sets starts at the null resource, so a stray index reads black.
    std::vector<VkDescriptorImageInfo> sampledInfos(
        kBindlessSampledCapacity, {VK_NULL_HANDLE, t.nullSampledView, VK_IMAGE_LAYOUT_GENERAL});
    std::vector<VkDescriptorImageInfo> storageInfos(
        kBindlessStorageCapacity, {VK_NULL_HANDLE, t.nullStorageView, VK_IMAGE_LAYOUT_GENERAL});
    for (VkDescriptorSet set : t.sets) {
        VkWriteDescriptorSet writes[2]{};
        writes[0] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        writes[0].dstSet = set;
        writes[0].dstBinding = 0;
        writes[0].descriptorCount = kBindlessSampledCapacity;
        writes[0].descriptorType = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
        writes[0].pImageInfo = sampledInfos.data();
        writes[1] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        writes[1].dstSet = set;
        writes[1].dstBinding = 1;
        writes[1].descriptorCount = kBindlessStorageCapacity;
        writes[1].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
        writes[1].pImageInfo = storageInfos.data();
        vkUpdateDescriptorSets(dev, 2, writes, 0, nullptr);
    }
}

void destroyBindless(Gpu& gpu) {
    BindlessTable& t = gpu.bindless;
    VkDevice dev = gpu.device.device;
    if (t.nullSampledView) vkDestroyImageView(dev, t.nullSampledView, nullptr);
    destroy(gpu, t.nullTexture);
    vkDestroyPipelineLayout(dev, t.pipelineLayout, nullptr);
    vkDestroyDescriptorPool(dev, t.pool, nullptr);
    vkDestroyDescriptorSetLayout(dev, t.layout, nullptr);
    for (VkSampler s : t.samplers) vkDestroySampler(dev, s, nullptr);
    t = BindlessTable{};
}

// Writes reach the set being recorded at once (the GPU finished with it before the frame
// began) and the other set when its frame comes round.
static void writeBoth(Gpu& gpu, const BindlessWrite& w) {
    BindlessTable& t = gpu.bindless;
    writeNow(gpu, t.sets[t.current], w);
    t.pending[t.current ^ 1].push_back(w);
}

BindlessSlot allocateBindless(Gpu& gpu, BindlessKind kind, VkImageView view, VkImageLayout layout) {
    BindlessTable& t = gpu.bindless;
    auto& freeList = kind == BindlessKind::Sampled ? t.freeSampled : t.freeStorage;
    uint32_t& next = kind == BindlessKind::Sampled ? t.nextSampled : t.nextStorage;
    uint32_t limit =
        kind == BindlessKind::Sampled ? kBindlessSampledStatic : kBindlessStorageStatic;
    uint32_t slot;
    if (!freeList.empty()) {
        slot = freeList.back();
        freeList.pop_back();
    } else {
        if (next >= limit)
            throw DeviceError(format("bindless table full: %u %s slots in use", limit,
                                     kind == BindlessKind::Sampled ? "sampled" : "storage"));
        slot = next++;
    }
    (kind == BindlessKind::Sampled ? t.staticSampledInUse : t.staticStorageInUse)++;
    writeBoth(gpu, {kind, slot, view, layout});
    return {slot};
}

// A newer write to a slot supersedes queued ones; dropping them also keeps a view that is
// destroyed right after being queued from ever reaching vkUpdateDescriptorSets.
static void dropPending(BindlessTable& t, BindlessKind kind, uint32_t slot) {
    for (auto& queue : t.pending)
        std::erase_if(queue,
                      [&](const BindlessWrite& w) { return w.kind == kind && w.slot == slot; });
}

void updateBindless(Gpu& gpu, BindlessKind kind, BindlessSlot slot, VkImageView view,
                    VkImageLayout layout) {
    // Content changes (streaming) keep the slot: the front set is untouched until its frame.
    BindlessTable& t = gpu.bindless;
    dropPending(t, kind, slot.value);
    t.pending[0].push_back({kind, slot.value, view, layout});
    t.pending[1].push_back({kind, slot.value, view, layout});
}

void freeBindless(Gpu& gpu, BindlessKind kind, BindlessSlot slot) {
    BindlessTable& t = gpu.bindless;
    dropPending(t, kind, slot.value);
    t.pending[0].push_back({kind, slot.value, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_GENERAL});
    t.pending[1].push_back({kind, slot.value, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_GENERAL});
    t.retired.push_back({kind, slot.value, 3u});
    (kind == BindlessKind::Sampled ? t.staticSampledInUse : t.staticStorageInUse)--;
}

BindlessSlot allocateDynamicBindless(Gpu& gpu, BindlessKind kind, VkImageView view,
                                     VkImageLayout layout) {
    BindlessTable& t = gpu.bindless;
    uint32_t& cursor = kind == BindlessKind::Sampled ? t.dynamicSampled : t.dynamicStorage;
    uint32_t base = kind == BindlessKind::Sampled ? kBindlessSampledStatic : kBindlessStorageStatic;
    uint32_t cap =
        kind == BindlessKind::Sampled ? kBindlessSampledCapacity : kBindlessStorageCapacity;
    if (base + cursor >= cap) throw DeviceError("bindless dynamic section full for this frame");
    uint32_t slot = base + cursor++;
    writeNow(gpu, t.sets[t.current], {kind, slot, view, layout});
    return {slot};
}

void prepareBindlessFrame(Gpu& gpu, uint64_t frameIndex) {
    BindlessTable& t = gpu.bindless;
    t.current = uint32_t(frameIndex & 1);
    for (const BindlessWrite& w : t.pending[t.current]) writeNow(gpu, t.sets[t.current], w);
    t.pending[t.current].clear();
    // Slots whose null write has now reached both sets can be reused.
    for (auto& r : t.retired) r.setsLeft &= ~(1u << t.current);
    auto done =
        std::stable_partition(t.retired.begin(), t.retired.end(),
                              [](const BindlessTable::Retired& r) { return r.setsLeft != 0; });
    for (auto it = done; it != t.retired.end(); ++it)
        (it->kind == BindlessKind::Sampled ? t.freeSampled : t.freeStorage).push_back(it->slot);
    t.retired.erase(done, t.retired.end());
    t.dynamicSampled = t.dynamicStorage = 0;
}

VkDescriptorSet currentBindlessSet(const Gpu& gpu) {
    return gpu.bindless.sets[gpu.bindless.current];
}

} // namespace shadel
