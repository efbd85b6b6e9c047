#version 460
// Mesh particles: opaque boxes on the forward path, PARTICLE_MESH_VERTICES vertices
// per particle slot (slots of sprite emitters and dead particles collapse to a point). Each box
// is scaled per axis and tumbles about a random axis, both from the particle's seed. Lit per
// vertex here (emitters flagged vertex-lit, or --particle-lighting vertex) or per pixel in
// mesh.frag, with wrap shading either way (shadeParticle, shaders/common/lighting.glsl).
#include "particles/particles.glsl"

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t particleFrame;
} pc;

layout(location = 0) out vec3 outPosition;
layout(location = 1) out vec3 outNormal;
layout(location = 2) flat out uint outParticle;
layout(location = 3) out vec3 outVertexLight; // x < 0: light per pixel

// The box's 6 faces: normal, and the two axes spanning it (counter-clockwise seen from outside).
const vec3 kFaceNormal[6] = vec3[](vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0), vec3(0, -1, 0),
                                   vec3(0, 0, 1), vec3(0, 0, -1));
const vec3 kFaceU[6] = vec3[](vec3(0, 1, 0), vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1),
                              vec3(1, 0, 0), vec3(-1, 0, 0));
const vec3 kFaceV[6] = vec3[](vec3(0, 0, 1), vec3(0, 0, 1), vec3(1, 0, 0), vec3(1, 0, 0),
                              vec3(0, 1, 0), vec3(0, 1, 0));
const vec2 kQuad[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1), vec2(1, 1), vec2(-1, 1));

// Rodrigues' rotation of v about the unit axis k by angle a.
vec3 rotate(vec3 v, vec3 k, float a) {
    float c = cos(a), s = sin(a);
    return v * c + cross(k, v) * s + k * dot(k, v) * (1.0 - c);
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ParticleFrame pf = ParticleFrameRef(pc.particleFrame).p;
    uint i = uint(gl_VertexIndex) / PARTICLE_MESH_VERTICES;
    uint corner = uint(gl_VertexIndex) % PARTICLE_MESH_VERTICES;
    GpuParticle p = ParticleBuffer(pf.particles).p[i];
    GpuParticleEmitter e = ParticleEmitterBuffer(pf.emitters).e[p.emitter];
    outParticle = i;
    outVertexLight = vec3(-1.0);
    outNormal = vec3(0.0, 1.0, 0.0);
    if (!particleAlive(p) || (e.flags & PARTICLE_EMITTER_MESH) == 0u) {
        outPosition = vec3(0.0);
        gl_Position = vec4(0.0, 0.0, -1.0, 1.0);
        return;
    }
    uint face = corner / 6u;
    vec2 q = kQuad[corner % 6u];
    // Face normal n with u x v = n, so (u, v) order gives counter-clockwise from outside.
    vec3 n = kFaceNormal[face];
    vec3 u = kFaceU[face], v = kFaceV[face];
    if (dot(cross(u, v), n) < 0.0) u = -u;
    vec3 local = n + q.x * u + q.y * v; // a corner of the [-1, 1]^3 box
    uint seed = particleSpriteSeed(e, i, p);
    vec3 scale = 0.5 * particleSize(e, p) *
                 vec3(0.6 + 0.4 * particleRandom(seed, 0u, 0u, 0u),
                      0.6 + 0.4 * particleRandom(seed, 0u, 0u, 1u),
                      0.6 + 0.4 * particleRandom(seed, 0u, 0u, 2u));
    vec3 axis = normalize(vec3(particleRandom(seed, 1u, 0u, 0u), particleRandom(seed, 1u, 0u, 1u),
                               particleRandom(seed, 1u, 0u, 2u)) - 0.5 + vec3(0.0, 0.0, 1e-3));
    float angle = p.rotation + 4.0 * p.age; // tumbling
    vec3 pos = p.position + rotate(local * scale, axis, angle);
    vec3 normal = normalize(rotate(n / scale, axis, angle));
    outPosition = pos;
    outNormal = normal;
    gl_Position = f.viewProj * vec4(pos, 1.0);
    if ((e.flags & PARTICLE_EMITTER_VERTEX_LIT) != 0u || pf.lighting == PARTICLE_LIGHTING_VERTEX)
        outVertexLight = shadeParticle(f, pos, normal, e.wrap);
}
