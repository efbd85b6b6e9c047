#include "render/debug/capture.h"

#include <cstring>

#include <glm/gtc/packing.hpp>

#include "core/error.h"
#include "core/log.h"
#include "rhi/gpu.h"

namespace shadel {

void registerCapture(CaptureRegistry& registry, std::string name, std::string what,
                     CaptureKind kind, std::function<CapturedImage()> read) {
    for (CaptureSource& s : registry.sources)
        if (s.name == name) { // a technique re-created (e.g. a new size) replaces its entry
            s = {std::move(name), std::move(what), kind, std::move(read)};
            return;
        }
    registry.sources.push_back({std::move(name), std::move(what), kind, std::move(read)});
}

const CaptureSource* findCapture(const CaptureRegistry& registry, const std::string& name) {
    for (const CaptureSource& s : registry.sources)
        if (s.name == name) return &s;
    return nullptr;
}

std::string captureNames(const CaptureRegistry& registry) {
    std::string names;
    for (const CaptureSource& s : registry.sources) names += (names.empty() ? "" : ", ") + s.name;
    return names;
}

namespace {
uint32_t texelBytes(VkFormat format) {
    switch (format) {
    case VK_FORMAT_R16G16B16A16_SFLOAT:
    case VK_FORMAT_R32G32_UINT:
        return 8;
    case VK_FORMAT_R32G32B32A32_SFLOAT:
        return 16;
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_R8G8B8A8_SRGB:
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_R32_UINT:
    case VK_FORMAT_R32_SFLOAT:
        return 4;
    default:
        return 0;
    }
}
} // namespace

CapturedImage readTexture(Gpu& gpu, TextureHandle texture, VkImageLayout layout, CaptureKind kind) {
    const TextureDesc& d = desc(gpu, texture);
    uint32_t bytesPerTexel = texelBytes(d.format);
    if (bytesPerTexel == 0)
        throw InputError(
            format("--capture %s: format %d cannot be captured", d.name.c_str(), int(d.format)));
    VkDeviceSize bytes = VkDeviceSize(d.width) * d.height * bytesPerTexel;
    BufferHandle staging = createBuffer(gpu, {"staging.capture", bytes, 0, MemoryKind::Readback});
    if (!staging) throw DeviceError(format("out of host memory to capture %s", d.name.c_str()));
    bool depth = isDepthFormat(d.format);
    VkImageAspectFlags aspect = depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    VkImage image = vkImage(gpu, texture);
    // A copy may read GENERAL directly; any other layout goes to TRANSFER_SRC and back.
    bool transition = layout != VK_IMAGE_LAYOUT_GENERAL;
    VkImageLayout copyLayout = transition ? VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL : layout;
    immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
        imageBarrier(cmd, image, aspect, layout, copyLayout, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                     VK_ACCESS_2_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                     VK_ACCESS_2_TRANSFER_READ_BIT, 0, 1);
        VkBufferImageCopy copy{};
        copy.imageSubresource = {aspect, 0, 0, 1};
        copy.imageExtent = {d.width, d.height, 1};
        vkCmdCopyImageToBuffer(cmd, image, copyLayout, vkBuffer(gpu, staging), 1, &copy);
        imageBarrier(cmd, image, aspect, copyLayout, layout, VK_PIPELINE_STAGE_2_COPY_BIT,
                     VK_ACCESS_2_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                     VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT, 0, 1);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    });
    const uint8_t* src = static_cast<const uint8_t*>(mapped(gpu, staging));
    CapturedImage out;
    out.kind = kind;
    out.width = d.width;
    out.height = d.height;
    size_t texels = size_t(d.width) * d.height;
    switch (d.format) {
    case VK_FORMAT_R16G16B16A16_SFLOAT: {
        out.channels = 4;
        out.floats.resize(texels * 4);
        for (size_t i = 0; i < texels * 4; ++i) {
            uint16_t h;
            std::memcpy(&h, src + i * 2, 2);
            out.floats[i] = glm::unpackHalf1x16(h);
        }
        break;
    }
    case VK_FORMAT_R32G32B32A32_SFLOAT:
        out.channels = 4;
        out.floats.resize(texels * 4);
        std::memcpy(out.floats.data(), src, bytes);
        break;
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_R32_SFLOAT:
        out.channels = 1;
        out.floats.resize(texels);
        std::memcpy(out.floats.data(), src, bytes);
        break;
    case VK_FORMAT_R32G32_UINT:
        out.channels = 2;
        out.uints.resize(texels * 2);
        std::memcpy(out.uints.data(), src, bytes);
        break;
    case VK_FORMAT_R32_UINT:
        out.channels = 1;
        out.uints.resize(texels);
        std::memcpy(out.uints.data(), src, bytes);
        break;
    default: // RGBA8
        out.channels = 4;
        out.rgba8.assign(src, src + bytes);
        break;
    }
    destroy(gpu, staging);
    return out;
}

void registerTextureCapture(CaptureRegistry& registry, Gpu& gpu, std::string name, std::string what,
                            CaptureKind kind, std::function<TextureHandle()> texture,
                            VkImageLayout layout) {
    registerCapture(registry, std::move(name), std::move(what), kind,
                    [&gpu, texture = std::move(texture), layout, kind] {
                        return readTexture(gpu, texture(), layout, kind);
                    });
}

CapturedImage readMaskGrid(Gpu& gpu, BufferHandle masks, uint32_t side) {
    size_t cells = size_t(side) * side;
    std::vector<uint8_t> bytes = readbackBuffer(gpu, masks, cells * 8);
    CapturedImage out;
    out.kind = CaptureKind::Mask;
    out.width = out.height = side;
    out.channels = 1;
    out.maskMax = 64;
    out.uints.resize(cells);
    for (size_t i = 0; i < cells; ++i) {
        uint64_t mask;
        std::memcpy(&mask, bytes.data() + i * 8, 8);
        out.uints[i] = uint32_t(__builtin_popcountll(mask));
    }
    return out;
}

CapturedImage readLabelGrid(Gpu& gpu, BufferHandle labels, uint32_t side) {
    size_t cells = size_t(side) * side;
    std::vector<uint8_t> bytes = readbackBuffer(gpu, labels, cells * 4);
    CapturedImage out;
    out.kind = CaptureKind::Labels;
    out.width = out.height = side;
    out.channels = 1;
    out.uints.resize(cells);
    std::memcpy(out.uints.data(), bytes.data(), cells * 4);
    return out;
}

} // namespace shadel
