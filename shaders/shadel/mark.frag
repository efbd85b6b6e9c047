#version 460
// Raster marking (--marking raster): the decoupled objects drawn again against the prepass
// depth, with no colour output; each visible pixel marks what reconstruction will read
// (shadel/marking.glsl).
#include "shadel/marking.glsl"

layout(early_fragment_tests) in;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint shadowView;
} pc;

layout(location = 4) flat in uint inInstance;
layout(location = 5) in vec2 inShadelUv;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    ShadelObjectRef o = shadelObject(s, inInstance);
    vec2 texel = inShadelUv * vec2(o.v.mip0Size);
    markSample(s, o, inShadelUv, dFdx(texel), dFdy(texel));
}
