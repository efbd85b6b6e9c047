#pragma once
// Buffers, textures and their typed views. Resources live in tables owned by the Gpu;
// callers hold handles (rhi/handles.h). Buffers are reached from shaders by device address,
// textures through views in the bindless table.
#include <string>
#include <vector>

#include "rhi/handles.h"
#include "rhi/memory.h"

namespace shadel {

struct Gpu;

struct BufferDesc {
    std::string name;
    VkDeviceSize size = 0;
    VkBufferUsageFlags usage = 0; // storage + device address are always added
    MemoryKind memory = MemoryKind::DeviceLocal;
};

struct TextureDesc {
    std::string name;
    VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
    uint32_t width = 1, height = 1;
    uint32_t mipLevels = 1;
    VkImageUsageFlags usage = VK_IMAGE_USAGE_SAMPLED_BIT;
    VkImageCreateFlags flags = 0; // e.g. MUTABLE_FORMAT: linear and sRGB views of one image
};

struct ViewDesc {
    uint32_t baseMip = 0;
    uint32_t mipCount = VK_REMAINING_MIP_LEVELS;
    VkFormat format = VK_FORMAT_UNDEFINED; // UNDEFINED = the texture's format
};

struct BufferRecord {
    VkBuffer buffer = VK_NULL_HANDLE;
    MemoryBlock memory;
    VkDeviceSize size = 0;
    VkDeviceAddress address = 0;
    std::string name;
};

struct TextureRecord {
    VkImage image = VK_NULL_HANDLE;
    MemoryBlock memory;
    TextureDesc desc;
    VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT;
};

struct ViewRecord {
    VkImageView view = VK_NULL_HANDLE;
    TextureHandle texture;
    BindlessSlot slot; // for read/write views
    uint32_t baseMip = 0, mipCount = 1;
};

// Returns an invalid handle when memory runs out (the caller decides how to degrade).
BufferHandle createBuffer(Gpu& gpu, const BufferDesc& desc);
TextureHandle createTexture(Gpu& gpu, const TextureDesc& desc);
void destroy(Gpu& gpu, BufferHandle buffer);
void destroy(Gpu& gpu, TextureHandle texture);

TextureReadView createReadView(Gpu& gpu, TextureHandle texture, const ViewDesc& desc = {});
TextureWriteView createWriteView(Gpu& gpu, TextureHandle texture, const ViewDesc& desc = {});
RenderTargetView createRenderTargetView(Gpu& gpu, TextureHandle texture, const ViewDesc& desc = {});
DepthTargetView createDepthTargetView(Gpu& gpu, TextureHandle texture, const ViewDesc& desc = {});
void destroy(Gpu& gpu, TextureReadView view);
void destroy(Gpu& gpu, TextureWriteView view);
void destroy(Gpu& gpu, RenderTargetView view);
void destroy(Gpu& gpu, DepthTargetView view);

// Accessors.
VkBuffer vkBuffer(const Gpu& gpu, BufferHandle buffer);
VkDeviceAddress address(const Gpu& gpu, BufferHandle buffer);
VkDeviceSize size(const Gpu& gpu, BufferHandle buffer);
void* mapped(const Gpu& gpu, BufferHandle buffer); // null for device-local buffers
VkImage vkImage(const Gpu& gpu, TextureHandle texture);
const TextureDesc& desc(const Gpu& gpu, TextureHandle texture);
VkImageView vkView(const Gpu& gpu, RenderTargetView view);
VkImageView vkView(const Gpu& gpu, DepthTargetView view);
// The image view behind a sampled view, only to point another bindless slot at it (texture
// streaming rebinds a texture's slot as it moves between cache layers). Not `vkView`: that
// overload set is for attachments, and a sampled view is not one (tests/compile_fail).
VkImageView sampledImageView(const Gpu& gpu, TextureReadView view);
TextureHandle textureOf(const Gpu& gpu, RenderTargetView view);
TextureHandle textureOf(const Gpu& gpu, DepthTargetView view);
TextureHandle textureOf(const Gpu& gpu, TextureReadView view);
TextureHandle textureOf(const Gpu& gpu, TextureWriteView view);
BindlessSlot slot(const Gpu& gpu, TextureReadView view);
BindlessSlot slot(const Gpu& gpu, TextureWriteView view);

bool isDepthFormat(VkFormat format);

} // namespace shadel
