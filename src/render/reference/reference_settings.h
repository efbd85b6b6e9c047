#pragma once
// What the reference path tracer (render/reference) is asked to do: the --spp, --max-bounces,
// --seed flags of --mode reference.
#include <cstdint>

namespace shadel {

struct ReferenceSettings {
    uint32_t samplesPerFrame = 4; // --spp: paths per pixel each frame adds to the mean
    uint32_t maxBounces = 16;     // --max-bounces: surface hits after the first (0: direct light)
    uint32_t rouletteStart = 3;   // bounces before Russian roulette may end a path
    uint32_t seed = 0;            // --seed: another seed, independent noise; the same, the same
};

} // namespace shadel
