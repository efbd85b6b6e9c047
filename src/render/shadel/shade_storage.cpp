#include "render/shadel/shade_storage.h"

#include <cstring>

#include <glm/gtc/packing.hpp>

#include "core/log.h"
#include "render/debug/capture.h"
#include "rhi/resources.h"

namespace shadel {

bool createShadeStorage(Gpu& gpu, uint32_t size, ShadeStorage& out) {
    static const char* layerNames[SHADEL_LAYERS] = {"radiance", "material"};
    out.size = size;
    VkDeviceSize shadels = VkDeviceSize(size) * size;
    for (uint32_t parity = 0; parity < 2; ++parity) {
        for (uint32_t layer = 0; layer < SHADEL_LAYERS; ++layer) {
            BufferDesc desc;
            desc.name = format("shadel.shadeStorage.%s.frame%u", layerNames[layer], parity);
            desc.size = shadels * kShadeLayerBytes[layer];
            desc.memory = MemoryKind::DeviceLocal;
            BufferHandle& b = out.frames[parity][layer];
            b = createBuffer(gpu, desc);
            if (!b) {
                destroyShadeStorage(gpu, out);
                return false;
            }
        }
    }
    // Zeroed once, so slots no chunk has written yet read (and capture) as black.
    immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
        for (auto& frame : out.frames)
            for (BufferHandle b : frame)
                vkCmdFillBuffer(cmd, vkBuffer(gpu, b), 0, VK_WHOLE_SIZE, 0);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    });
    return true;
}

void destroyShadeStorage(Gpu& gpu, ShadeStorage& storage) {
    for (auto& frame : storage.frames)
        for (BufferHandle& b : frame) {
            if (b) destroy(gpu, b);
            b = BufferHandle{};
        }
}

CapturedImage readShadeLayerAtlas(Gpu& gpu, const ShadeStorage& storage, uint32_t parity,
                                  uint32_t layer) {
    uint32_t side = storage.size, chunksPerRow = side / SHADEL_CHUNK;
    uint32_t texelBytes = kShadeLayerBytes[layer];
    std::vector<uint8_t> linear =
        readbackBuffer(gpu, storage.frames[parity][layer], VkDeviceSize(side) * side * texelBytes);
    // The atlas in rows, as the image it replaces was laid out.
    std::vector<uint8_t> atlas(linear.size());
    for (uint32_t y = 0; y < side; ++y)
        for (uint32_t cx = 0; cx < chunksPerRow; ++cx) {
            uint32_t slot = (y / SHADEL_CHUNK) * chunksPerRow + cx;
            size_t from =
                (size_t(slot) * SHADEL_CHUNK * SHADEL_CHUNK + (y % SHADEL_CHUNK) * SHADEL_CHUNK) *
                texelBytes;
            size_t to = (size_t(y) * side + size_t(cx) * SHADEL_CHUNK) * texelBytes;
            std::memcpy(atlas.data() + to, linear.data() + from, SHADEL_CHUNK * texelBytes);
        }
    CapturedImage out;
    out.width = out.height = side;
    out.channels = 4;
    if (layer == SHADEL_LAYER_RADIANCE) {
        out.kind = CaptureKind::Hdr;
        out.floats.resize(atlas.size() / 2);
        for (size_t i = 0; i < out.floats.size(); ++i) {
            uint16_t h;
            std::memcpy(&h, atlas.data() + i * 2, 2);
            out.floats[i] = glm::unpackHalf1x16(h);
        }
    } else {
        out.kind = CaptureKind::Display;
        out.rgba8 = std::move(atlas);
    }
    return out;
}

} // namespace shadel
