#version 460
// Particle lightmap atlas: one 8x8 workgroup per particle; a lit sprite with an atlas
// rectangle lights every texel of it from the sprite's position and normal map with the full
// light list (shadeParticle, shaders/common/lighting.glsl), at unit albedo.
#include "particles/particles.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t particleFrame;
} pc;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ParticleFrame pf = ParticleFrameRef(pc.particleFrame).p;
    uint i = gl_WorkGroupID.x;
    GpuParticle p = ParticleBuffer(pf.particles).p[i];
    if (p.atlasEntry == PARTICLE_NO_ATLAS) return; // uniform over the workgroup
    ParticleAtlasCountsRef counts = ParticleAtlasCountsRef(pf.atlasCounts);
    uint lod = p.atlasEntry >> 24;
    uvec4 rect = particleAtlasRect(counts.c.perLod, lod, p.atlasEntry & 0xFFFFFFu, pf.atlasSize);
    if (rect.w == 0u) {
        if (gl_LocalInvocationIndex == 0u) atomicAdd(counts.c.overflowed, 1u);
        return;
    }
    if (gl_LocalInvocationIndex == 0u) atomicAdd(counts.c.texels, rect.z * rect.z);
    GpuParticleEmitter e = ParticleEmitterBuffer(pf.emitters).e[p.emitter];
    for (uint y = gl_LocalInvocationID.y; y < rect.z; y += 8u)
        for (uint x = gl_LocalInvocationID.x; x < rect.z; x += 8u) {
            vec2 uv = (vec2(x, y) + 0.5) / float(rect.z);
            vec3 light = particleLightingAt(f, e, p, i, uv);
            imageStore(gImagesRgba16f[pf.atlasWriteSlot], ivec2(rect.xy + uvec2(x, y)),
                       vec4(min(light, vec3(60000.0)), 1.0));
        }
}
