#version 460
// WBOIT composite, before tonemapping: the accumulated transparent layers over the opaque scene
// colour (blended: dst = rgb + dst * revealage; see wboitComposite).
#include "oit/wboit.glsl"

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint accumSlot;
    uint revealSlot;
    // Half-resolution particle targets (render/particles), NO_TEXTURE without them: WBOIT sums
    // the colour and additiveness and multiplies the revealage, so the two accumulations
    // combine exactly before the resolve; the half-resolution one is read bilinearly.
    uint halfAccumSlot;
    uint halfRevealSlot;
} pc;

layout(location = 0) out vec4 outColor;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 accum = fetchTextureUniform(pc.accumSlot, p, 0);
    vec4 reveal = fetchTextureUniform(pc.revealSlot, p, 0);
    if (pc.halfAccumSlot != NO_TEXTURE) {
        vec2 uv = (vec2(p) + 0.5) / vec2(textureSize(gTextures[pc.revealSlot], 0));
        vec4 halfAccum = sampleTextureLod(pc.halfAccumSlot, SAMPLER_LINEAR_CLAMP, uv, 0.0);
        vec4 halfReveal = sampleTextureLod(pc.halfRevealSlot, SAMPLER_LINEAR_CLAMP, uv, 0.0);
        accum += halfAccum;
        reveal = vec4(reveal.rg * halfReveal.rg, reveal.b, reveal.a + halfReveal.a);
    }
    outColor = wboitComposite(accum, reveal);
}
