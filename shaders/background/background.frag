#version 460
// The background behind the opaque surfaces: a full-screen triangle at the far plane, depth
// tested EQUAL against the cleared depth, so only pixels no surface covers run it. Alpha 0: the
// pixel stays uncovered (the readback's coverage).
#include "background/background.glsl"
#include "common/tone_curve.glsl"

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint unused;
} pc;

layout(location = 0) out vec4 outColor;

// Display pixels (the frame's tonemap fused into the colour pass), else scene colour.
layout(constant_id = 0) const bool kDisplayOutput = false;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    vec3 c = backgroundAt(f, gl_FragCoord.xy);
    outColor = vec4(kDisplayOutput ? displayColor(c, f.exposure, f.tonemap) : c, 0.0);
}
