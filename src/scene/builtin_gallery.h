#pragma once
// builtin:textures: a corridor of 64 panels, each with its own procedural texture (2048^2 at
// full scale: 1 GiB of level-0 texels, 1.33 GiB with MIPs), for texture streaming
// (render/streaming). The texels are generated when the streaming file is built.
#include <cstdint>

#include "scene/scene.h"

namespace shadel {

constexpr uint32_t kGalleryPanels = 64;
constexpr uint32_t kGalleryFullTextureSize = 2048;

// textureSize: every texture's side (a power of two; 0 = full scale). Tests use small sizes.
Scene makeTextureGallery(uint32_t textureSize = 0);

} // namespace shadel
