#include "render/shadel/shade_storage.h"

#include "core/log.h"
#include "rhi/resources.h"

namespace shadel {

bool createShadeStorage(Gpu& gpu, uint32_t size, ShadeStorage& out) {
    static const char* layerNames[SHADEL_LAYERS] = {"radiance", "material"};
    static const VkFormat layerFormats[SHADEL_LAYERS] = {VK_FORMAT_R16G16B16A16_SFLOAT,
                                                         VK_FORMAT_R8G8B8A8_UNORM};
    out.size = size;
    for (uint32_t parity = 0; parity < 2; ++parity) {
        for (uint32_t layer = 0; layer < SHADEL_LAYERS; ++layer) {
            TextureDesc desc;
            desc.name = format("shadel.shadeStorage.%s.frame%u", layerNames[layer], parity);
            desc.format = layerFormats[layer];
            desc.width = desc.height = size;
            desc.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
            ShadeLayer& l = out.frames[parity][layer];
            l.texture = createTexture(gpu, desc);
            if (!l.texture) {
                destroyShadeStorage(gpu, out);
                return false;
            }
            l.write = createWriteView(gpu, l.texture);
            l.read = createReadView(gpu, l.texture);
        }
    }
    immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
        for (auto& frame : out.frames)
            for (ShadeLayer& l : frame)
                imageBarrier(cmd, vkImage(gpu, l.texture), VK_IMAGE_ASPECT_COLOR_BIT,
                             VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
                             VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                             VK_ACCESS_2_SHADER_READ_BIT);
    });
    return true;
}

void destroyShadeStorage(Gpu& gpu, ShadeStorage& storage) {
    for (auto& frame : storage.frames)
        for (ShadeLayer& l : frame) {
            if (l.write) destroy(gpu, l.write);
            if (l.read) destroy(gpu, l.read);
            if (l.texture) destroy(gpu, l.texture);
            l = ShadeLayer{};
        }
}

} // namespace shadel
