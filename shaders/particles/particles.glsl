// What every particle pass shares: the buffers, the deterministic hash the emitters spawn from,
// a particle's look over its life, the camera-plane billboard, and the sprite texture (opacity
// and tangent-space normal map, procedural: the same function at any resolution, so the atlas
// and per-pixel lighting sample one normal map).
#ifndef SHADEL_PARTICLES_GLSL
#define SHADEL_PARTICLES_GLSL
#include "common/lighting.glsl"
#include "particles/particle_types.h"
#include "particles/particle_atlas.h"

layout(buffer_reference, scalar) readonly buffer ParticleFrameRef { ParticleFrame p; };
layout(buffer_reference, scalar) buffer ParticleBuffer { GpuParticle p[]; };
layout(buffer_reference, scalar) readonly buffer ParticleEmitterBuffer { GpuParticleEmitter e[]; };
layout(buffer_reference, scalar) buffer ParticleAtlasCountsRef { ParticleAtlasCounts c; };

// PCG hash (Jarzynski & Olano 2020): integer in, integer out, identical on every device.
uint particleHash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}
float particleRandom(uint seed, uint particle, uint generation, uint channel) {
    uint h = particleHash(seed ^ particleHash(particle ^ particleHash(generation * 16u + channel)));
    return float(h >> 8) * (1.0 / 16777216.0);
}

bool particleAlive(GpuParticle p) {
    return p.generation != PARTICLE_NOT_SPAWNED && p.age >= 0.0 && p.age < p.lifetime;
}
float particleLife(GpuParticle p) { return clamp(p.age / p.lifetime, 0.0, 1.0); }
float particleSize(GpuParticleEmitter e, GpuParticle p) {
    return mix(e.sizeStart, e.sizeEnd, particleLife(p));
}
// Colour and opacity over the particle's life: faded in over the first 10%, out over the last 40%.
vec4 particleColor(GpuParticleEmitter e, GpuParticle p) {
    float t = particleLife(p);
    vec4 c = mix(e.colorStart, e.colorEnd, t);
    c.a *= smoothstep(0.0, 0.1, t) * (1.0 - smoothstep(0.6, 1.0, t));
    return c;
}

// Billboard axes: the camera's right and up, turned by the particle's rotation (every sprite
// lies in a plane parallel to the image plane, so the atlas and the raster see the same quad).
struct ParticleBasis {
    vec3 right, up, towardCamera;
};
ParticleBasis particleBasis(FrameConstants f, GpuParticle p) {
    vec3 camRight = vec3(f.view[0][0], f.view[1][0], f.view[2][0]);
    vec3 camUp = vec3(f.view[0][1], f.view[1][1], f.view[2][1]);
    ParticleBasis b;
    float c = cos(p.rotation), s = sin(p.rotation);
    b.right = c * camRight + s * camUp;
    b.up = -s * camRight + c * camUp;
    b.towardCamera = vec3(f.view[0][2], f.view[1][2], f.view[2][2]);
    return b;
}
// The sprite's point at uv in [0, 1]^2.
vec3 particlePoint(ParticleBasis b, GpuParticle p, float size, vec2 uv) {
    vec2 o = (uv - 0.5) * size;
    return p.position + o.x * b.right + o.y * b.up;
}

// Value noise, smooth (C1): the sprite's breakup.
float particleNoise(vec2 x, uint seed) {
    vec2 i = floor(x), fr = fract(x);
    vec2 u = fr * fr * (3.0 - 2.0 * fr);
    uint sx = uint(int(i.x) & 0xFFFF), sy = uint(int(i.y) & 0xFFFF);
    float a = float(particleHash(seed ^ (sx | sy << 16)) >> 8) / 16777216.0;
    float b2 = float(particleHash(seed ^ ((sx + 1u) & 0xFFFFu | sy << 16)) >> 8) / 16777216.0;
    float c = float(particleHash(seed ^ (sx | ((sy + 1u) & 0xFFFFu) << 16)) >> 8) / 16777216.0;
    float d = float(particleHash(seed ^ ((sx + 1u) & 0xFFFFu | ((sy + 1u) & 0xFFFFu) << 16)) >> 8) / 16777216.0;
    return mix(mix(a, b2, u.x), mix(c, d, u.x), u.y);
}

// The puff's height field: a low dome with two octaves of noise (the normal map's source).
float puffHeight(vec2 q, uint seed) {
    float dome = 0.55 * (1.0 - dot(q, q));
    return dome + 0.22 * particleNoise(q * 2.5 + 7.0, seed) + 0.08 * particleNoise(q * 5.0 + 3.0, seed + 1u);
}

// The sprite texture at uv: opacity (a soft disc broken up by noise) and the normal map
// (tangent space, z towards the camera) from the height field's gradient. Separate functions:
// sprites lit from the atlas never evaluate the normal map per pixel.
float particleSpriteOpacity(vec2 uv, uint seed) {
    vec2 q = uv * 2.0 - 1.0;
    float disc = clamp(1.0 - dot(q, q), 0.0, 1.0);
    return disc * disc * (0.6 + 0.4 * particleNoise(q * 3.0 + 11.0, seed + 2u));
}
vec3 particleSpriteNormal(vec2 uv, uint seed, float normalScale) {
    vec2 q = uv * 2.0 - 1.0;
    const float e = 1.0 / 64.0;
    float hx = puffHeight(q + vec2(e, 0.0), seed) - puffHeight(q - vec2(e, 0.0), seed);
    float hy = puffHeight(q + vec2(0.0, e), seed) - puffHeight(q - vec2(0.0, e), seed);
    return normalize(vec3(-hx / (2.0 * e) * normalScale, -hy / (2.0 * e) * normalScale, 1.0));
}
vec3 particleWorldNormal(ParticleBasis b, vec3 tangentNormal) {
    return normalize(tangentNormal.x * b.right + tangentNormal.y * b.up +
                     tangentNormal.z * b.towardCamera);
}
uint particleSpriteSeed(GpuParticleEmitter e, uint particle, GpuParticle p) {
    return particleHash(e.seed ^ particleHash(particle * 65536u + p.generation));
}

// The lighting of a lit sprite at uv (unit albedo): what the atlas stores per texel and the
// per-pixel path evaluates per fragment, from the one normal map.
vec3 particleLightingAt(FrameConstants f, GpuParticleEmitter e, GpuParticle p, uint particle,
                        vec2 uv) {
    ParticleBasis b = particleBasis(f, p);
    vec3 n = particleSpriteNormal(uv, particleSpriteSeed(e, particle, p), e.normalScale);
    vec3 pos = particlePoint(b, p, particleSize(e, p), uv);
    return shadeParticle(f, pos, particleWorldNormal(b, n), e.wrap);
}
#endif
