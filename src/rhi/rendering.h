#pragma once
// Dynamic rendering with the attachments passes actually use: colour targets that load or
// clear, an optional depth target, the full render area, and the viewport and scissor set to
// it (every pass here draws the whole target). Pair with vkCmdEndRendering.
#include <initializer_list>

#include "rhi/vk.h"

namespace shadel {

struct ColorAttachment {
    VkImageView view = VK_NULL_HANDLE; // in COLOR_ATTACHMENT_OPTIMAL
    bool clear = false;                // else load
    VkClearColorValue clearValue{};
};

struct DepthAttachment {
    VkImageView view = VK_NULL_HANDLE; // none when null; in DEPTH_ATTACHMENT_OPTIMAL
    bool clear = false;                // else load
    float clearDepth = 0.0f;           // reversed Z: 0 is far
};

void beginRendering(VkCommandBuffer cmd, uint32_t width, uint32_t height,
                    std::initializer_list<ColorAttachment> colors, DepthAttachment depth = {});

} // namespace shadel
