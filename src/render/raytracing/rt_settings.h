#pragma once
// What the ray-tracing part (render/raytracing) is asked to do: the --rt-* flags.
#include <cstdint>

namespace shadel {

struct RtSettings {
    bool shadows = false; // --rt-shadows: the sun's and the shadow-casting spots' visibility traced
                          // instead of their shadow maps
    bool ao = false;      // --rt-ao: ray-traced ambient occlusion
    bool gi = false;      // --rt-gi: one bounce of ray-traced diffuse light
    // Sun rays per sample: 1 = hard shadows, more = soft (jittered over the sun's disc).
    uint32_t shadowRays = 1;
    float sunAngleDegrees = 0.5f; // half angle of the sun's disc (soft shadows)
    uint32_t aoRays = 4;          // forward: AO rays per pixel
    float aoRadius = 1.0f;        // world units
    uint32_t giRays = 1;          // forward: GI rays per pixel
    bool spatialFilter = true;    // forward: 3x3 depth-aware filter of the noisy terms
    uint32_t raysPerShadel = 1;   // shadel path: AO / GI rays per shadel per frame
    uint32_t shadelMipOffset = 2; // shadel path: the RT cache's MIP, this much coarser than needed
    uint32_t historyRays = 256;   // shadel path: rays per texel after which it is reused as it is
    // BLAS memory: pools of this size, sub-allocated with TLSF, at most this many.
    uint32_t blasPoolMb = 128;
    uint32_t blasPoolLimit = 16;
    float distance = 0.0f; // TLAS instances within this distance of the camera (0 = all)
    // GPU-skinned meshes get their own BLAS, refit as the pose changes (off: the bind pose's
    // static BLAS, the comparison of the animated-BLAS test).
    bool animatedBlas = true;

    bool enabled() const { return shadows || ao || gi; }
};

} // namespace shadel
