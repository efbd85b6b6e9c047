#version 460
// Mesh particles: opaque, the emitter's colour over life as albedo, lit per vertex (from the
// vertex shader) or per pixel, both with wrap shading.
#include "particles/particles.glsl"

layout(early_fragment_tests) in;
layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t particleFrame;
} pc;

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) flat in uint inParticle;
layout(location = 3) in vec3 inVertexLight;

layout(location = 0) out vec4 outColor;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ParticleFrame pf = ParticleFrameRef(pc.particleFrame).p;
    GpuParticle p = ParticleBuffer(pf.particles).p[inParticle];
    GpuParticleEmitter e = ParticleEmitterBuffer(pf.emitters).e[p.emitter];
    vec3 albedo = mix(e.colorStart.rgb, e.colorEnd.rgb, particleLife(p));
    vec3 light = inVertexLight;
    if (light.r < 0.0) light = shadeParticle(f, inPosition, normalize(inNormal), e.wrap);
    outColor = vec4(albedo * light, 1.0);
}
