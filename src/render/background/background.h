#pragma once
// The environment behind the scene in the raster colour passes (forward shading, decoupled
// reconstruction): drawn after the opaque surfaces where none covers the pixel. A solid
// --background colour needs no draw: the colour passes clear to it.
#include "rhi/vk.h"

namespace shadel {
struct Renderer;
void createBackgroundPipelines(Renderer& r);
void destroyBackgroundPipelines(Renderer& r);
// Inside an open colour pass over the scene depth: the scene colour target, or the display
// target of a fused tonemap.
void recordBackground(Renderer& r, VkCommandBuffer cmd, uint64_t frame, bool display);
} // namespace shadel
