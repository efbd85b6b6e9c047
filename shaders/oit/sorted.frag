#version 460
// The sorted reference (--oit sorted): transparent surfaces drawn back to front (sorted on the
// CPU per instance, back faces before front faces) with premultiplied "over" blending, where
// an additive fragment has opacity 0 and simply adds.
#include "oit/transparent_shading.glsl"

layout(early_fragment_tests) in;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint shadowView;
} pc;

layout(location = 0) out vec4 outColor;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    TransparentFragment t = shadeTransparentFragment(f);
    outColor = vec4(t.premultiplied, transparentOpacity(t));
}
