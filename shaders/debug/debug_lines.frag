#version 460
// Debug lines are emissive: bright enough after exposure and the tone curve to read on any
// surface (the HDR target is tonemapped after this pass).
#include "common/bindless.glsl"

layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;
layout(location = 0) in vec3 inColor;
layout(location = 0) out vec4 outColor;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    outColor = vec4(inColor * 2.0 / max(f.exposure, 1e-6), 1.0);
}
