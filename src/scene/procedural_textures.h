#pragma once
// Textures made by code (builtin:textures): deterministic functions of (kind, seed, texel), so a
// gigabyte of texels needs no storage in the scene; the streaming file is built from them.
#include <cstdint>

#include "scene/scene.h"

namespace shadel {

constexpr uint32_t kProceduralTextureKinds = 4; // kinds 1..4

// Writes size x size RGBA8 texels (sRGB-encoded colour, alpha 255) of texture `t` at full
// resolution `size` (a power of two). Detail exists down to the single texel, so every MIP
// level differs from the next: streaming a level too coarse shows in the image.
void generateProceduralTexture(const ProceduralTexture& t, uint32_t size, uint8_t* rgba);

} // namespace shadel
