#pragma once
// The shade storage (about 4k x 4k shadels by default): one buffer per material layer, all sharing
// the chunk slot allocation, and two frames of each so a chunk can carry last frame's shadels over
// (preserved layers, an exact previous-sample lookup). Chunk-linear: shadel (x, y) of the chunk in
// slot s is element s * 64 + y * 8 + x (shaders/shadel/shadel.glsl storageIndex), so a chunk is
// contiguous and a shader reads a shadel with one buffer load.
#include <array>

#include "common/shared_types.h"
#include "rhi/gpu.h"

namespace shadel {

struct CapturedImage;

// Bytes per shadel of each layer: radiance RGBA16F (uvec2 of packHalf2x16), material RGBA8
// (uint of packUnorm4x8). Both are the bytes of the matching image format's texel.
inline constexpr uint32_t kShadeLayerBytes[SHADEL_LAYERS] = {8, 4};

struct ShadeStorage {
    uint32_t size = 0; // shadels per side: size^2 shadels, (size / 8)^2 chunk slots
    std::array<std::array<BufferHandle, SHADEL_LAYERS>, 2> frames{}; // [frame parity][layer]
};

// Creates every layer of both frames for size x size shadels, zeroed. Returns false (and leaves
// nothing allocated) when GPU memory runs out, so the caller can try a smaller size.
bool createShadeStorage(Gpu& gpu, uint32_t size, ShadeStorage& out);
void destroyShadeStorage(Gpu& gpu, ShadeStorage& storage);

// One layer read back and laid out as a size x size atlas, slot s's chunk at chunk column
// s % (size / 8), row s / (size / 8) (what --capture storage.* shows): radiance as Hdr floats,
// material as Display RGBA8. Only after the frame's GPU work has finished.
CapturedImage readShadeLayerAtlas(Gpu& gpu, const ShadeStorage& storage, uint32_t parity,
                                  uint32_t layer);

} // namespace shadel
