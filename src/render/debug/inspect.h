#pragma once
// --inspect X,Y: of the shaderPrint records a frame produced at the inspected pixel, the ones of
// the fragment the frame shows (shaders/debug/inspect.glsl tags each fragment's records and
// prints its depth; with reversed Z the front fragment has the largest depth).
#include <vector>

#include "rhi/shader_messages.h"

namespace shadel {

struct InspectedPixel {
    std::vector<ShaderPrint> prints; // the front fragment's records, in order
    uint32_t fragments = 0;          // fragments that were shaded at the pixel
};

InspectedPixel frontFragment(const std::vector<ShaderPrint>& prints);

} // namespace shadel
