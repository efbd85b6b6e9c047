#pragma once
// What the reference path tracer keeps between frames (render/reference/reference.h).
#include <cstdint>

#include <glm/mat4x4.hpp>

#include "rhi/gpu.h"
#include "rhi/pipeline.h"

namespace shadel {

struct ReferenceState {
    // The mean radiance of every path so far (rgb) and their coverage (a), RGBA32F at the
    // internal resolution; left in GENERAL layout.
    TextureHandle accumulation;
    TextureWriteView accumulationWrite;
    TextureWriteView hdrWrite; // the scene colour, written with the mean for the tonemap
    Pipeline pathTrace;
    bool alpha = false;               // the scene has alpha-masked or blended materials
    uint32_t samplesAccumulated = 0;  // paths per pixel in the mean
    uint32_t restarts = 0;            // the camera moved and the mean started again
    bool laidOut = false;             // the accumulation left UNDEFINED layout
    glm::mat4 view{0.0f}, proj{0.0f}; // the camera of the mean
};

} // namespace shadel
