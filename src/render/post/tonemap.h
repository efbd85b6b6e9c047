#pragma once
// Tonemapping + SSAA resolve + coverage: HDR target -> RGBA8 pixels in a readback buffer.
#include "rhi/vk.h"

namespace shadel {
struct Renderer;
void createTonemapPipeline(Renderer& r);
void recordTonemap(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
} // namespace shadel
