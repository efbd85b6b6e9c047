// Light propagation volume layouts shared by C++ (render/gi) and GLSL (shaders/gi).
// C++ includes this inside namespace shadel::gpu through shared_types.h's conventions.
#ifndef SHADEL_GI_TYPES_H
#define SHADEL_GI_TYPES_H

#ifdef __cplusplus
#include "common/shared_types.h"
namespace shadel::gpu {
#endif

#define GI_CASCADES 3u // camera-centred cascades, each twice the cell size of the last
// Fixed volumes an artist places (a glTF node's extras "shadel_gi_volume"): the same grid over
// a box of the scene, injected and propagated once, and read before the cascades where they hold
// a point.
#define GI_MAX_LOCAL_VOLUMES 2u
#define GI_MAX_VOLUMES (GI_CASCADES + GI_MAX_LOCAL_VOLUMES)
#define GI_GRID 32u    // cells per side of every cascade
#define GI_MAX_RSMS 3u // the sun + up to two shadow-casting spots
// Injection adds fixed-point integers (no float atomics are required of the device): one unit
// is 2^-20 of a radiant-intensity SH coefficient.
#define GI_FIXED_SCALE 1048576.0
// Per cell of the injection buffer: 12 ints of radiance SH (R, G, B x 4) + 4 of geometry SH.
#define GI_INJECT_INTS 16u

#define GI_MAX_BLOCKERS 64u // a macro-cell's blocker list is one 64-bit mask
#define GI_MACRO 4u         // cells per side of a macro-cell (the apply's blocker culling)
#define GI_MACRO_GRID (GI_GRID / GI_MACRO)

// A light blocker for GI: a rectangle light does not propagate through (render/gi/lpv.h), with
// portals (holes light passes through, as in direct lighting).
struct GpuGiBlocker {
    vec3 center;
    float halfU;
    vec3 axisU; // unit
    float halfV;
    vec3 axisV;   // unit, orthogonal to axisU
    uint portals; // first | count << 16 into GiFrame::portals
};

// One volume (a camera cascade or a local volume) as the apply reads it.
struct GiCascade {
    vec3 origin;       // world position of the min corner of cell (0, 0, 0)
    float cellSize;    // metres per cell
    uint64_t radiance; // vec4[3] per cell: propagated radiant intensity, SH (R, G, B)
    uint64_t geometry; // vec4 per cell: blocking potential, SH (geometry volume)
    // uint64 per macro-cell (GI_MACRO^3 cells): bit k = blocker k can cut a segment that starts
    // in the macro-cell and ends within one cell of it (the apply's and injection's taps).
    uint64_t blockerCells;
};

struct GiFrame {
    // The local volumes first, then the camera cascades finest first: the apply takes a point's
    // light from the first volume that holds it (blending across each one's border band).
    GiCascade cascades[GI_MAX_VOLUMES];
    uint cascadeCount; // volumes in use: local volumes + GI_CASCADES
    float intensity;   // scale of the indirect term (1 = physical estimate)
    uint blockerCount; // light blockers: the apply drops trilinear taps behind one
    uint pad0;
    uint64_t blockers; // GpuGiBlocker[blockerCount]
    uint64_t portals;  // vec4 per portal: min u, min v, max u, max v (metres from the centre)
    uint blockerCells; // 1: test only a macro-cell's blockers (0: all, for comparison)
    uint pad1;
};

#ifdef __cplusplus
} // namespace shadel::gpu
#endif
#endif
