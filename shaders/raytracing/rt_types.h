// Ray tracing layouts shared by C++ (render/raytracing) and GLSL (shaders/raytracing).
#ifndef SHADEL_RT_TYPES_H
#define SHADEL_RT_TYPES_H

#ifdef __cplusplus
#include "common/shared_types.h"
namespace shadel::gpu {
#endif

// Counted on the GPU, read back after the frame (stats rays_traced).
struct RtCounters {
    uint raysTraced; // every rayQueryInitializeEXT of the frame
    uint pad0;
    uint pad1;
    uint pad2;
};

// Shadel path: an instance's ray-traced terms live in a persistent atlas (the RT cache) at one
// MIP of its shadel space, coarser than the lit layer; rays accumulate there over frames.
#define RT_SHADEL_VALID 1u // the instance has a rect in the cache this frame
#define RT_SHADEL_RESET 2u // its history is void (new rect, moved, or a changed input): restart
// Reading the cache: a texel holding fewer rays than this borrows its neighbours' (a wider,
// ray-count-weighted filter blended out as the rays accumulate; raytracing/rt_apply.glsl).
#define RT_SHADEL_FILTER_RAYS 16.0

struct RtShadelObject {
    uvec2 origin;     // texel of the atlas where the rect starts
    uvec2 size;       // the level's size (texels = shadels of that MIP)
    uint level;       // MIP of the object's shadel space
    uint idMapOffset; // of that level, in 16-bit units into ShadelFrame::idMaps
    uint flags;       // RT_SHADEL_*
    uint pad;
};

// One 8x8 tile of a cached rect to trace this frame (a workgroup).
struct RtShadelTile {
    uint object;
    uint tile; // x | y << 16, in tiles of the rect
};

// What the ray-tracing passes and the shading that reads their results share
// (FrameConstants::rt, 0 when no ray-traced effect is on).
struct RtFrame {
    uint64_t tlas;          // VkAccelerationStructureKHR device address (rayQuery from uint64)
    uint64_t instanceLods;  // uint per instance: first index of the LOD its BLAS was built from
    uint64_t counters;      // RtCounters
    uint shadows;           // 1: the sun's visibility is traced (--rt-shadows on)
    uint ao;                // 1: --rt-ao on
    uint gi;                // 1: --rt-gi on
    uint shadowRays;        // rays per sample toward the sun: 1 = hard, more = soft (jittered)
    float sunAngle;         // half angle of the sun's disc (radians) for soft shadows
    uint aoRays;            // AO rays per sample (a pixel, or a shadel per frame)
    float aoRadius;         // AO rays end here (world units)
    uint giRays;            // one-bounce diffuse rays per sample
    uint pixelTermsSlot;    // forward: bindless read slot of the traced terms, or NO_TEXTURE
    uint pixelIndirectSlot; // forward: bindless read slot of the traced indirect light
    uint frame;             // frame number (decorrelates the random sequences)
    uint spatialFilter;     // forward: 1 = 3x3 depth-aware filter of AO and GI when read
    float normalOffset;     // ray origins move this far along the normal, per unit of distance
    uint raysPerShadel;     // shadel path: AO / GI rays per cached texel per frame
    uint64_t shadelObjects; // RtShadelObject per instance, 0 when not decoupled
    uint64_t shadelTiles;   // RtShadelTile[shadelTileCount]
    uint shadelTileCount;
    uint historyRays; // a texel with this many rays accumulated is done: no more are traced
    uint
        shadelTermsWrite; // cache atlas: sun, AO, normal oct x, rays accumulated (storage, rgba16f)
    uint shadelTermsRead; //   ... the same, sampled
    uint shadelIndirectWrite; // cache atlas: indirect light, normal oct y
    uint shadelIndirectRead;
    // Spot shadows (--rt-shadows on, scenes with shadow-casting spots): the visibility of every
    // shadow-casting spot (by GpuLight::shadowIndex), 8 bits each, packed in a uvec4 per sample
    // (packed by rtSpotVisibilities in raytracing/rt_effects.glsl, read by rtSpotVisibility in
    // common/lighting.glsl).
    uint spotShadowCount; // shadow-casting spots traced (<= LIGHT_MAX_SPOT_SHADOWS), 0: none
    uint64_t spotLights;  // uint per shadow index: the light's index in FrameConstants::lights
    uint pixelSpotSlot;   // forward: bindless read slot of the traced spot visibilities (uint)
    uint shadelSpotWrite; // cache atlas: spot visibilities (storage, rgba32ui)
    uint shadelSpotRead;  //   ... the same, sampled
    // Shadel path: a cached texel's side in pixels is its world side * this / its distance;
    // this is scaled so that 1 is half the side the cache's MIP was chosen for (at the
    // instance's nearest point). A 2x2 block of texels below it (far parts of large objects)
    // is traced once, into a history its texels share (rt_shadels.comp).
    float shadelTexelPixelScale;
};

#ifdef __cplusplus
} // namespace shadel::gpu
#endif
#endif
