#version 460
// Particle sprites: six vertices per particle slot (two triangles of the camera-plane quad),
// pulled from the particle buffer; dead or unborn particles collapse to a point (no fragments).
// No sorting: the sprites go to the WBOIT targets (shaders/oit/wboit.glsl).
#include "particles/particles.glsl"

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t particleFrame;
} pc;

layout(location = 0) out vec3 outPosition;
layout(location = 1) out vec2 outUv;
layout(location = 2) flat out uint outParticle;
layout(location = 3) out vec3 outVertexLight; // --particle-lighting vertex
layout(location = 4) flat out uvec4 outAtlasRect; // x, y, side, fits (0: none)

const vec2 kCorners[6] = vec2[](vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 0), vec2(1, 1), vec2(0, 1));

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ParticleFrame pf = ParticleFrameRef(pc.particleFrame).p;
    uint i = uint(gl_VertexIndex) / 6u;
    vec2 uv = kCorners[uint(gl_VertexIndex) % 6u];
    GpuParticle p = ParticleBuffer(pf.particles).p[i];
    outParticle = i;
    outUv = uv;
    outVertexLight = vec3(0.0);
    outAtlasRect = uvec4(0u);
    GpuParticleEmitter e = ParticleEmitterBuffer(pf.emitters).e[p.emitter];
    if (!particleAlive(p) || (e.flags & PARTICLE_EMITTER_MESH) != 0u) {
        outPosition = vec3(0.0);
        gl_Position = vec4(0.0, 0.0, -1.0, 1.0); // every vertex alike: a degenerate triangle
        return;
    }
    ParticleBasis b = particleBasis(f, p);
    vec3 pos = particlePoint(b, p, particleSize(e, p), uv);
    outPosition = pos;
    gl_Position = f.viewProj * vec4(pos, 1.0);
    // The sprite's atlas rectangle, once per vertex rather than per fragment.
    if (p.atlasEntry != PARTICLE_NO_ATLAS)
        outAtlasRect = particleAtlasRect(ParticleAtlasCountsRef(pf.atlasCounts).c.perLod,
                                         p.atlasEntry >> 24, p.atlasEntry & 0xFFFFFFu, pf.atlasSize);
    if ((e.flags & PARTICLE_EMITTER_LIT) != 0u && pf.lighting == PARTICLE_LIGHTING_VERTEX) {
        // The corner's normal: the dome of the normal map without its noise (the corners
        // themselves lie outside the disc, so take the disc's edge towards them).
        vec2 q = normalize(uv * 2.0 - 1.0);
        vec3 n = normalize(vec3(1.1 * q * e.normalScale, 1.0));
        outVertexLight = shadeParticle(f, pos, particleWorldNormal(b, n), e.wrap);
    }
}
