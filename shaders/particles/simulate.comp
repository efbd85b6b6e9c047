#version 460
// GPU particle simulation (one thread per particle): `steps` fixed time steps of births,
// motion (velocity, buoyancy/gravity, drag, a swirl) and respawns, all seeded by the emitter's
// seed, the particle's index and its generation, so a run is reproducible frame for frame.
// Then each live lit sprite (not mesh particles: they take the forward path) asks the particle atlas for a rectangle at the LOD its estimated
// screen size calls for (particles/particle_atlas.h): one atomic per sprite is its packing.
#include "particles/particles.glsl"

layout(local_size_x = 64) in;
layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t particleFrame;
} pc;

void spawn(GpuParticleEmitter e, uint index, inout GpuParticle p, uint generation) {
    p.generation = generation;
    float angle = 6.2831853 * particleRandom(e.seed, index, generation, 0u);
    float radius = e.spawnRadius * sqrt(particleRandom(e.seed, index, generation, 1u));
    p.position = e.position + vec3(cos(angle) * radius, 0.0, sin(angle) * radius);
    vec3 jitter = vec3(particleRandom(e.seed, index, generation, 2u),
                       particleRandom(e.seed, index, generation, 3u),
                       particleRandom(e.seed, index, generation, 4u)) * 2.0 - 1.0;
    p.velocity = e.velocity + jitter * e.velocitySpread;
    p.lifetime = e.lifetime * (0.8 + 0.4 * particleRandom(e.seed, index, generation, 5u));
    p.rotation = 6.2831853 * particleRandom(e.seed, index, generation, 6u);
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ParticleFrame pf = ParticleFrameRef(pc.particleFrame).p;
    uint i = gl_GlobalInvocationID.x;
    if (i >= pf.particleCount) return;
    ParticleBuffer particles = ParticleBuffer(pf.particles);
    GpuParticle p = particles.p[i];
    GpuParticleEmitter e = ParticleEmitterBuffer(pf.emitters).e[p.emitter];
    uint local = i - e.firstParticle;
    for (uint s = 0u; s < pf.steps; ++s) {
        float t = pf.time + float(s) * pf.dt;
        p.age += pf.dt;
        if (p.age < 0.0) continue; // not born yet
        if (p.generation == PARTICLE_NOT_SPAWNED) {
            spawn(e, local, p, 0u);
        } else if (p.age >= p.lifetime) {
            p.age -= p.lifetime;
            spawn(e, local, p, p.generation + 1u);
        }
        vec3 swirl = e.turbulence * vec3(sin(p.position.y * 2.1 + t * 1.3 + float(local)),
                                         0.0, cos(p.position.y * 1.7 + t * 0.9 + float(local) * 1.7));
        p.velocity += (e.acceleration + swirl) * pf.dt;
        p.velocity *= max(1.0 - e.drag * pf.dt, 0.0);
        p.position += p.velocity * pf.dt;
        if (e.bounce >= 0.0 && p.position.y < 0.0) { // the ground plane
            p.position.y = -p.position.y * e.bounce;
            p.velocity = vec3(p.velocity.x * 0.7, -p.velocity.y * e.bounce, p.velocity.z * 0.7);
        }
    }

    p.atlasEntry = PARTICLE_NO_ATLAS;
    if (particleAlive(p) && (e.flags & (PARTICLE_EMITTER_LIT | PARTICLE_EMITTER_MESH)) == PARTICLE_EMITTER_LIT &&
        pf.lighting == PARTICLE_LIGHTING_ATLAS) {
        float size = particleSize(e, p);
        bool visible = true;
        for (int k = 0; k < 6; ++k)
            visible = visible && dot(f.frustumPlanes[k].xyz, p.position) + f.frustumPlanes[k].w >= -size;
        float viewDepth = -(f.view * vec4(p.position, 1.0)).z;
        if (visible && viewDepth > 1e-3) {
            // Estimated screen size: the sprite's height over the viewport's height.
            float screenFraction = size * abs(f.proj[1][1]) / (2.0 * viewDepth);
            uint lod = particleAtlasLod(screenFraction, e.lodBias);
            uint index = atomicAdd(ParticleAtlasCountsRef(pf.atlasCounts).c.perLod[lod], 1u);
            p.atlasEntry = lod << 24 | index;
        }
    }
    particles.p[i] = p;
}
