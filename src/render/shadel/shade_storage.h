#pragma once
// The shade storage (seed: "actual storage is ~4kx4k"): one texture per material layer, all
// sharing the chunk slot allocation, and two frames of each so a chunk can carry last frame's
// shadels over (preserved layers, seed: "GetIndexPrevSampleVirtualCoords").
#include <array>

#include "common/shared_types.h"
#include "rhi/gpu.h"

namespace shadel {

struct ShadeLayer {
    TextureHandle texture;
    TextureWriteView write;
    TextureReadView read;
};

struct ShadeStorage {
    uint32_t size = 0;                                             // shadels per side
    std::array<std::array<ShadeLayer, SHADEL_LAYERS>, 2> frames{}; // [frame parity][layer]
};

// Creates every layer of both frames at size x size, in GENERAL layout. Returns false (and
// leaves nothing allocated) when GPU memory runs out, so the caller can try a smaller size.
bool createShadeStorage(Gpu& gpu, uint32_t size, ShadeStorage& out);
void destroyShadeStorage(Gpu& gpu, ShadeStorage& storage);

} // namespace shadel
