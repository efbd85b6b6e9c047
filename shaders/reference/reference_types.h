// The reference path tracer's push constants, shared by C++ (render/reference) and GLSL
// (shaders/reference).
#ifndef SHADEL_REFERENCE_TYPES_H
#define SHADEL_REFERENCE_TYPES_H

#ifdef __cplusplus
#include "common/shared_types.h"
namespace shadel::gpu {
#endif

#define REFERENCE_GROUP_SIZE 8u
// The scene has alpha-masked or alpha-blended materials: rays see every triangle as a candidate
// and test its alpha (blended: stochastically); without them every triangle is opaque.
#define REFERENCE_FLAG_ALPHA 1u

struct ReferencePush {
    uint64_t frame;        // FrameConstants
    uint accumulationSlot; // storage rgba32f: the mean of every path so far (rgb), coverage (a)
    uint hdrSlot;          // storage rgba16f: the scene colour the tonemap reads
    uint width;            // internal resolution
    uint height;
    uint samplesBefore; // paths per pixel already in the mean (0: this frame starts it)
    uint samples;       // paths per pixel this frame
    uint maxBounces;
    uint rouletteStart;
    uint seed;
    uint flags; // REFERENCE_FLAG_*
};

#ifdef __cplusplus
} // namespace shadel::gpu
#endif
#endif
