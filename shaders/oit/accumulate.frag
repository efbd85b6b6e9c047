#version 460
// WBOIT accumulation (--oit wboit): every transparent surface, in any order, adds its weighted
// premultiplied colour and coverage, multiplies the revealage and adds its additiveness.
// Tested against the opaque depth, never against each other (no depth writes).
#include "oit/transparent_shading.glsl"

layout(early_fragment_tests) in;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint shadowView;
} pc;

layout(location = 0) out vec4 outAccum;
layout(location = 1) out vec4 outReveal;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    TransparentFragment t = shadeTransparentFragment(f);
    wboitOutputs(t, viewDepthOf(f, inPosition), outAccum, outReveal);
}
