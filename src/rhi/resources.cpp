#include "rhi/resources.h"

#include "core/assert.h"
#include "core/log.h"
#include "rhi/gpu.h"

namespace shadel {

bool isDepthFormat(VkFormat format) {
    return format == VK_FORMAT_D32_SFLOAT || format == VK_FORMAT_D16_UNORM ||
           format == VK_FORMAT_D24_UNORM_S8_UINT || format == VK_FORMAT_D32_SFLOAT_S8_UINT;
}

static bool hasStencil(VkFormat format) {
    return format == VK_FORMAT_D24_UNORM_S8_UINT || format == VK_FORMAT_D32_SFLOAT_S8_UINT;
}

BufferHandle createBuffer(Gpu& gpu, const BufferDesc& desc) {
    SHADEL_ASSERT(desc.size > 0);
    VkBufferCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    ci.size = desc.size;
    ci.usage = desc.usage | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
               VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
               VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    ci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    BufferRecord rec;
    rec.size = desc.size;
    rec.name = desc.name;
    if (VkResult res = vkCreateBuffer(gpu.device.device, &ci, nullptr, &rec.buffer);
        res != VK_SUCCESS) {
        gpu.failedAllocations++;
        SHADEL_WARN("cannot create buffer %s (%llu bytes): %s", desc.name.c_str(),
                    (unsigned long long)desc.size, vkResultName(res));
        return {};
    }
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(gpu.device.device, rec.buffer, &req);
    auto block = allocateMemory(gpu.memory, desc.memory, req);
    if (!block) {
        vkDestroyBuffer(gpu.device.device, rec.buffer, nullptr);
        gpu.failedAllocations++;
        SHADEL_WARN("out of GPU memory for buffer %s (%llu bytes)", desc.name.c_str(),
                    (unsigned long long)desc.size);
        return {};
    }
    rec.memory = *block;
    VK_CHECK(
        vkBindBufferMemory(gpu.device.device, rec.buffer, rec.memory.memory, rec.memory.offset));
    VkBufferDeviceAddressInfo ai{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
    ai.buffer = rec.buffer;
    rec.address = vkGetBufferDeviceAddress(gpu.device.device, &ai);
    setName(gpu.device, rec.buffer, VK_OBJECT_TYPE_BUFFER, desc.name);
    return BufferHandle{gpu.buffers.add(std::move(rec))};
}

TextureHandle createTexture(Gpu& gpu, const TextureDesc& desc) {
    SHADEL_ASSERT(desc.width > 0 && desc.height > 0 && desc.mipLevels > 0);
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = desc.format;
    ci.extent = {desc.width, desc.height, 1};
    ci.flags = desc.flags;
    ci.mipLevels = desc.mipLevels;
    ci.arrayLayers = 1;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.tiling = VK_IMAGE_TILING_OPTIMAL;
    ci.usage = desc.usage | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    TextureRecord rec;
    rec.desc = desc;
    rec.aspect = isDepthFormat(desc.format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    if (hasStencil(desc.format)) rec.aspect |= VK_IMAGE_ASPECT_STENCIL_BIT;
    if (VkResult res = vkCreateImage(gpu.device.device, &ci, nullptr, &rec.image);
        res != VK_SUCCESS) {
        gpu.failedAllocations++;
        SHADEL_WARN("cannot create texture %s (%ux%u): %s", desc.name.c_str(), desc.width,
                    desc.height, vkResultName(res));
        return {};
    }
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(gpu.device.device, rec.image, &req);
    auto block = allocateMemory(gpu.memory, MemoryKind::DeviceLocal, req);
    if (!block) {
        vkDestroyImage(gpu.device.device, rec.image, nullptr);
        gpu.failedAllocations++;
        SHADEL_WARN("out of GPU memory for texture %s (%ux%u)", desc.name.c_str(), desc.width,
                    desc.height);
        return {};
    }
    rec.memory = *block;
    VK_CHECK(vkBindImageMemory(gpu.device.device, rec.image, rec.memory.memory, rec.memory.offset));
    setName(gpu.device, rec.image, VK_OBJECT_TYPE_IMAGE, desc.name);
    return TextureHandle{gpu.textures.add(std::move(rec))};
}

void destroy(Gpu& gpu, BufferHandle buffer) {
    if (!buffer) return;
    BufferRecord& rec = gpu.buffers[buffer.index];
    vkDestroyBuffer(gpu.device.device, rec.buffer, nullptr);
    freeMemory(gpu.memory, rec.memory);
    gpu.buffers.remove(buffer.index);
}

void destroy(Gpu& gpu, TextureHandle texture) {
    if (!texture) return;
    TextureRecord& rec = gpu.textures[texture.index];
    vkDestroyImage(gpu.device.device, rec.image, nullptr);
    freeMemory(gpu.memory, rec.memory);
    gpu.textures.remove(texture.index);
}

static ViewRecord makeView(Gpu& gpu, TextureHandle texture, const ViewDesc& desc,
                           const char* suffix) {
    SHADEL_ASSERT(gpu.textures.contains(texture.index));
    const TextureRecord& tex = gpu.textures[texture.index];
    ViewRecord rec;
    rec.texture = texture;
    rec.baseMip = desc.baseMip;
    rec.mipCount = desc.mipCount == VK_REMAINING_MIP_LEVELS ? tex.desc.mipLevels - desc.baseMip
                                                            : desc.mipCount;
    SHADEL_ASSERT(rec.baseMip + rec.mipCount <= tex.desc.mipLevels);
    VkImageViewCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    ci.image = tex.image;
    ci.viewType = VK_IMAGE_VIEW_TYPE_2D;
    ci.format = desc.format == VK_FORMAT_UNDEFINED ? tex.desc.format : desc.format;
    // Views see depth only; stencil is reached through the attachment.
    VkImageAspectFlags aspect =
        isDepthFormat(tex.desc.format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    ci.subresourceRange = {aspect, rec.baseMip, rec.mipCount, 0, 1};
    VK_CHECK(vkCreateImageView(gpu.device.device, &ci, nullptr, &rec.view));
    setName(gpu.device, rec.view, VK_OBJECT_TYPE_IMAGE_VIEW,
            format("%s.%s", tex.desc.name.c_str(), suffix));
    return rec;
}

TextureReadView createReadView(Gpu& gpu, TextureHandle texture, const ViewDesc& desc) {
    SHADEL_ASSERT(gpu.textures[texture.index].desc.usage & VK_IMAGE_USAGE_SAMPLED_BIT);
    ViewRecord rec = makeView(gpu, texture, desc, "read");
    VkImageLayout layout = (gpu.textures[texture.index].desc.usage & VK_IMAGE_USAGE_STORAGE_BIT)
                               ? VK_IMAGE_LAYOUT_GENERAL
                               : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    rec.slot = allocateBindless(gpu, BindlessKind::Sampled, rec.view, layout);
    return TextureReadView{gpu.readViews.add(rec)};
}

TextureWriteView createWriteView(Gpu& gpu, TextureHandle texture, const ViewDesc& desc) {
    SHADEL_ASSERT(gpu.textures[texture.index].desc.usage & VK_IMAGE_USAGE_STORAGE_BIT);
    ViewDesc one = desc;
    if (one.mipCount == VK_REMAINING_MIP_LEVELS) one.mipCount = 1; // storage views see one mip
    ViewRecord rec = makeView(gpu, texture, one, "write");
    rec.slot = allocateBindless(gpu, BindlessKind::Storage, rec.view, VK_IMAGE_LAYOUT_GENERAL);
    return TextureWriteView{gpu.writeViews.add(rec)};
}

RenderTargetView createRenderTargetView(Gpu& gpu, TextureHandle texture, const ViewDesc& desc) {
    const TextureRecord& tex = gpu.textures[texture.index];
    SHADEL_ASSERT(tex.desc.usage & VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
    SHADEL_ASSERT(!isDepthFormat(tex.desc.format));
    ViewDesc one = desc;
    one.mipCount = 1;
    return RenderTargetView{gpu.targetViews.add(makeView(gpu, texture, one, "target"))};
}

DepthTargetView createDepthTargetView(Gpu& gpu, TextureHandle texture, const ViewDesc& desc) {
    const TextureRecord& tex = gpu.textures[texture.index];
    SHADEL_ASSERT(tex.desc.usage & VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
    SHADEL_ASSERT(isDepthFormat(tex.desc.format));
    ViewDesc one = desc;
    one.mipCount = 1;
    return DepthTargetView{gpu.depthViews.add(makeView(gpu, texture, one, "depth"))};
}

void destroy(Gpu& gpu, TextureReadView view) {
    if (!view) return;
    ViewRecord& rec = gpu.readViews[view.index];
    freeBindless(gpu, BindlessKind::Sampled, rec.slot);
    vkDestroyImageView(gpu.device.device, rec.view, nullptr);
    gpu.readViews.remove(view.index);
}

void destroy(Gpu& gpu, TextureWriteView view) {
    if (!view) return;
    ViewRecord& rec = gpu.writeViews[view.index];
    freeBindless(gpu, BindlessKind::Storage, rec.slot);
    vkDestroyImageView(gpu.device.device, rec.view, nullptr);
    gpu.writeViews.remove(view.index);
}

void destroy(Gpu& gpu, RenderTargetView view) {
    if (!view) return;
    vkDestroyImageView(gpu.device.device, gpu.targetViews[view.index].view, nullptr);
    gpu.targetViews.remove(view.index);
}

void destroy(Gpu& gpu, DepthTargetView view) {
    if (!view) return;
    vkDestroyImageView(gpu.device.device, gpu.depthViews[view.index].view, nullptr);
    gpu.depthViews.remove(view.index);
}

VkBuffer vkBuffer(const Gpu& gpu, BufferHandle b) {
    return gpu.buffers[b.index].buffer;
}
VkDeviceAddress address(const Gpu& gpu, BufferHandle b) {
    return gpu.buffers[b.index].address;
}
VkDeviceSize size(const Gpu& gpu, BufferHandle b) {
    return gpu.buffers[b.index].size;
}
void* mapped(const Gpu& gpu, BufferHandle b) {
    return gpu.buffers[b.index].memory.mapped;
}
VkImage vkImage(const Gpu& gpu, TextureHandle t) {
    return gpu.textures[t.index].image;
}
const TextureDesc& desc(const Gpu& gpu, TextureHandle t) {
    return gpu.textures[t.index].desc;
}
VkImageView vkView(const Gpu& gpu, RenderTargetView v) {
    return gpu.targetViews[v.index].view;
}
VkImageView vkView(const Gpu& gpu, DepthTargetView v) {
    return gpu.depthViews[v.index].view;
}
VkImageView sampledImageView(const Gpu& gpu, TextureReadView v) {
    return gpu.readViews[v.index].view;
}
TextureHandle textureOf(const Gpu& gpu, RenderTargetView v) {
    return gpu.targetViews[v.index].texture;
}
TextureHandle textureOf(const Gpu& gpu, DepthTargetView v) {
    return gpu.depthViews[v.index].texture;
}
TextureHandle textureOf(const Gpu& gpu, TextureReadView v) {
    return gpu.readViews[v.index].texture;
}
TextureHandle textureOf(const Gpu& gpu, TextureWriteView v) {
    return gpu.writeViews[v.index].texture;
}
BindlessSlot slot(const Gpu& gpu, TextureReadView v) {
    return gpu.readViews[v.index].slot;
}
BindlessSlot slot(const Gpu& gpu, TextureWriteView v) {
    return gpu.writeViews[v.index].slot;
}

} // namespace shadel
