#version 460
// WBOIT composite, before tonemapping: the accumulated transparent layers over the opaque scene
// colour (blended: dst = rgb + dst * revealage; see wboitComposite).
#include "oit/wboit.glsl"

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint accumSlot;
    uint revealSlot;
} pc;

layout(location = 0) out vec4 outColor;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 accum = fetchTextureUniform(pc.accumSlot, p, 0);
    vec4 reveal = fetchTextureUniform(pc.revealSlot, p, 0);
    outColor = wboitComposite(accum, reveal);
}
