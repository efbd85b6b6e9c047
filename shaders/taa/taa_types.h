// Push constants of the temporal anti-aliasing passes, shared by C++ (render/taa) and GLSL.
#ifndef SHADEL_TAA_TYPES_H
#define SHADEL_TAA_TYPES_H

#ifdef __cplusplus
#include "common/shared_types.h"
namespace shadel::gpu {
#endif

#define TAA_GROUP_X 8u // the resolve and sharpen passes' workgroups
#define TAA_GROUP_Y 8u
// TaaResolvePush::flags
#define TAA_HISTORY_VALID 1u // the history holds an earlier frame of this view
// TaaResolvePush::counters: uint[TAA_COUNTER_COUNT], cleared before the resolve.
#define TAA_COUNTER_REJECTED 0u // pixels whose history failed the depth test or left the screen
#define TAA_COUNTER_CLIPPED 1u  // pixels whose history was moved into the neighbourhood's box
#define TAA_COUNTER_COUNT 2u

struct TaaResolvePush {
    mat4 prevViewProj; // last frame's unjittered view-projection
    uint64_t frame;    // FrameConstants (this frame's jittered matrices, exposure)
    uint64_t counters; // uint[TAA_COUNTER_COUNT]
    // This frame's jitter: the unjittered image position of what a pixel centre shows is that
    // centre plus this (pixels).
    vec2 jitter;
    vec2 prevJitter; // last frame's: where its stored depths were sampled
    uint width, height;
    uint hdrSlot;        // sampled: this frame's scene colour
    uint depthSlot;      // sampled: this frame's depth (reversed Z)
    uint historySlot;    // sampled: last frame's resolved colour (rgb) + inverse depth (a)
    uint outputSlot;     // storage rgba16f: this frame's resolved colour + inverse depth
    float currentWeight; // the exponential blend's weight of this frame (at least)
    uint flags;          // TAA_HISTORY_VALID
};

struct TaaSharpenPush {
    uint64_t frame;
    uint width, height;
    uint inputSlot;  // sampled: the resolved colour
    uint outputSlot; // storage rgba16f: sharpened
    float amount;    // 0..1
    uint pad;
};

#ifdef __cplusplus
} // namespace shadel::gpu
#endif
#endif
