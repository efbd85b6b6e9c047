#pragma once
// --inspect X,Y: of the shader print records a frame produced at the inspected pixel, the ones of
// the fragment the frame shows (shaders/debug/inspect.glsl tags each fragment's records and
// prints its depth; with reversed Z the front fragment has the largest depth).
#include <cstdint>
#include <utility>
#include <vector>

#include "rhi/shader_messages.h"

namespace shadel {

struct InspectedPixel {
    std::vector<ShaderPrint> prints; // the front fragment's records, in order
    uint32_t fragments = 0;          // fragments that were shaded at the pixel
};

InspectedPixel frontFragment(const std::vector<ShaderPrint>& prints);

// The specialization constant that compiles the inspect prints in (shaders/common/
// shader_print.glsl, constant_id 200). Off, the prints are dead code the driver removes: on
// lavapipe the forward shader with them compiled in but never taken ran 2x slower.
constexpr uint32_t kShaderPrintSpecId = 200;
inline std::vector<std::pair<uint32_t, uint32_t>> shaderPrintSpecialization(bool inspect) {
    if (!inspect) return {};
    return {{kShaderPrintSpecId, 1u}};
}

} // namespace shadel
