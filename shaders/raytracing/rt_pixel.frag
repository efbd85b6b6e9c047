#version 460
// Forward path: the ray-traced terms of every opaque pixel (drawn with the prepass depth, equal
// test), read by forward shading through raytracing/rt_apply.glsl. Target 0: sun visibility,
// AO, unused, distance to the camera (0 = nothing traced, for the filter); target 1: one-bounce
// indirect light; target 2: the shadow-casting spots' visibilities (8 bits each). A new random rotation every frame: per-pixel results are noisy over time.
#include "raytracing/rt_effects.glsl"

// The depth test before the shader: a fragment the prepass hid must not trace (nor count) rays;
// with atomics in the shader, late tests would run it for every fragment drawn.
layout(early_fragment_tests) in;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint shadowView;
} pc;

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inTangent;
layout(location = 3) in vec2 inUv;
layout(location = 7) in vec2 inUv1; // the second UV set (TEXCOORD_1)
layout(location = 4) flat in uint inInstance;

layout(location = 0) out vec4 outTerms;
layout(location = 1) out vec4 outIndirect;
layout(location = 2) out uvec4 outSpots;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    RtFrame rt = RtFrameRef(f.rt).r;
    GpuInstance inst = InstanceBuffer(f.instances).i[inInstance];
    GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
    SurfaceInput s;
    s.position = inPosition;
    s.normal = normalize(inNormal);
    s.tangent = inTangent;
    s.uv = inUv;
    s.uvDx = dFdx(inUv);
    s.uvDy = dFdy(inUv);
    s.uv1 = inUv1;
    s.uv1Dx = dFdx(inUv1);
    s.uv1Dy = dFdy(inUv1);
    s.frontFacing = gl_FrontFacing;
    MaterialSample m = evaluateMaterial(mat, s);
    if ((mat.flags & MATERIAL_ALPHA_MASK) != 0u && m.alpha < mat.alphaCutoff) discard;
    vec3 ng = normalize(cross(dFdx(inPosition), dFdy(inPosition)));
    // Helper invocations only serve the derivatives above: they trace (and count) nothing.
    if (gl_HelperInvocation) {
        outTerms = vec4(0.0);
        outIndirect = vec4(0.0);
        outSpots = uvec4(0xFFFFFFFFu);
        return;
    }
    if (dot(ng, f.cameraPosition - inPosition) < 0.0) ng = -ng;
    vec3 n = dot(m.normal, ng) < 0.0 ? -m.normal : m.normal; // the side the camera sees
    uint seed = rtHash(uint(gl_FragCoord.x) | uint(gl_FragCoord.y) << 16) ^ rtHash(rt.frame + 1u);
    float sun = rt.shadows != 0u ? rtSunVisibility(f, rt, inPosition, ng, seed, 0u) : 1.0;
    float ao = rt.ao != 0u ? rtAmbientOcclusion(f, rt, inPosition, n, ng, seed, 0u, rt.aoRays) : 1.0;
    vec3 indirect = rt.gi != 0u ? rtIndirectDiffuse(f, rt, inPosition, n, ng, seed, 0u, rt.giRays) : vec3(0.0);
    outSpots = rt.spotShadowCount != 0u ? rtSpotVisibilities(f, rt, inPosition, ng, seed ^ 0x7a3c1u, 0u)
                                        : uvec4(0xFFFFFFFFu);
    outTerms = vec4(sun, ao, 0.0, max(length(inPosition - f.cameraPosition), 1e-6));
    outIndirect = vec4(indirect, 1.0);
}
