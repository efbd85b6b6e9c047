// The particle lightmap atlas: the LOD a lit sprite gets from its estimated screen
// size, and where a sprite's rectangle lies in this frame's packing. Shared by C++ (tests) and
// GLSL (simulate.comp counts, atlas_light.comp writes, sprite.frag reads), so both agree.
//
// LODs: LOD 0 is 128x128 texels and each LOD is 3/4 of the one above it (rounded to a multiple
// of 4, at least 8), so one LOD per 25% less screen size keeps atlas texels per screen pixel
// roughly constant. A sprite at least PARTICLE_NEAR_SCREEN_FRACTION of the viewport height
// ("near the camera") gets PARTICLE_ATLAS_DEFAULT_LOD, 32x32; each 25% it
// shrinks from there drops one LOD; the emitter's artist bias is added (-5: LOD 0).
//
// Packing: every frame, from scratch (sprites come and go every frame), a shelf packer by LOD:
// LOD 0's sprites fill rows of 128-texel shelves from the top of the atlas, LOD 1's the rows
// below, and so on. A sprite's rectangle follows from the per-LOD counts and its index among
// its LOD's sprites alone, so the GPU packs with one atomic per sprite and no CPU round trip.
// Sizes sorted from large to small waste at most one partial row per LOD.
#ifndef SHADEL_PARTICLE_ATLAS_H
#define SHADEL_PARTICLE_ATLAS_H

#ifdef __cplusplus
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
namespace shadel::gpu {
using uint = uint32_t;
#endif

#define PARTICLE_ATLAS_LODS 10u
#define PARTICLE_ATLAS_DEFAULT_LOD 5u // 32x32
#define PARTICLE_NEAR_SCREEN_FRACTION 0.25f
#define PARTICLE_LOD_STEP 0.75f // one LOD per 25% less screen size

// Counters of one frame's atlas, cleared before the simulation.
struct ParticleAtlasCounts {
    uint perLod[PARTICLE_ATLAS_LODS]; // sprites that asked for each LOD
    uint overflowed;                  // sprites whose rectangle fell outside the atlas
    uint texels;                      // texels lit (sum of the rectangles that fit)
};

#ifdef __cplusplus
#define PA_INLINE inline
#define PA_UVEC2 glm::uvec2
#define PA_UVEC4 glm::uvec4
#define PA_MAX std::max
#define PA_MIN std::min
#else
#define PA_INLINE
#define PA_UVEC2 uvec2
#define PA_UVEC4 uvec4
#define PA_MAX max
#define PA_MIN min
#endif

// Side in texels of an LOD's square rectangle: 128, 96, 72, 56, 40, 32, 24, 16, 12, 8.
PA_INLINE uint particleAtlasSide(uint lod) {
    const uint sides[PARTICLE_ATLAS_LODS] = {128u, 96u, 72u, 56u, 40u, 32u, 24u, 16u, 12u, 8u};
    return sides[PA_MIN(lod, PARTICLE_ATLAS_LODS - 1u)];
}

// screenFraction: the sprite's estimated height on screen over the viewport height.
PA_INLINE uint particleAtlasLod(float screenFraction, float bias) {
    float steps = 0.0f;
    if (screenFraction < PARTICLE_NEAR_SCREEN_FRACTION)
        steps = floor(log(PARTICLE_NEAR_SCREEN_FRACTION / PA_MAX(screenFraction, 1e-6f)) /
                      log(1.0f / PARTICLE_LOD_STEP));
    float lod = float(PARTICLE_ATLAS_DEFAULT_LOD) + bias + steps;
    return uint(PA_MIN(PA_MAX(lod, 0.0f), float(PARTICLE_ATLAS_LODS - 1u)));
}

// The rectangle (x, y, side, fits) of the index-th sprite of `lod` in an atlas of `atlasSize`
// texels per side, given every LOD's count.
PA_INLINE PA_UVEC4 particleAtlasRect(const uint perLod[PARTICLE_ATLAS_LODS], uint lod, uint index,
                                     uint atlasSize) {
    uint y = 0u;
    for (uint l = 0u; l < lod; ++l) {
        uint side = particleAtlasSide(l);
        uint perRow = atlasSize / side;
        y += ((perLod[l] + perRow - 1u) / perRow) * side;
    }
    uint side = particleAtlasSide(lod);
    uint perRow = atlasSize / side;
    uint x = (index % perRow) * side;
    y += (index / perRow) * side;
    uint fits = y + side <= atlasSize ? 1u : 0u;
    return PA_UVEC4(x, y, side, fits);
}

#ifdef __cplusplus
} // namespace shadel::gpu
#endif
#undef PA_INLINE
#undef PA_UVEC2
#undef PA_UVEC4
#undef PA_MAX
#undef PA_MIN
#endif
