#version 460
// --visualize particle-atlas: the atlas (this frame's lighting, unit albedo) over the image,
// its width fitted to the viewport's, from the top (the shelves fill it top down); texels
// outside every rectangle are black (the atlas is cleared in this mode), rows below the atlas
// dark grey.
#include "particles/particles.glsl"

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t particleFrame;
} pc;

layout(location = 0) out vec4 outColor;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ParticleFrame pf = ParticleFrameRef(pc.particleFrame).p;
    vec2 uv = gl_FragCoord.xy / f.viewportSize.x;
    if (uv.y > 1.0) {
        outColor = vec4(0.02, 0.02, 0.02, 1.0);
        return;
    }
    ivec2 texel = ivec2(uv * float(pf.atlasSize));
    outColor = vec4(fetchTexture(pf.atlasReadSlot, texel, 0).rgb, 1.0);
}
