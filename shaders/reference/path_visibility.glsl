// What the reference path tracer's rays hit. Scenes without alpha: every triangle is opaque and
// the traversal commits the closest. With alpha-masked or alpha-blended materials
// (REFERENCE_FLAG_ALPHA) every triangle comes up as a candidate (gl_RayFlagsNoOpaqueEXT) and is
// committed only when it is opaque there: masked ones by their alpha test, blended ones with
// the probability of their alpha (stochastic transparency, a coin per ray and triangle that
// does not depend on the traversal order).
#ifndef SHADEL_PATH_VISIBILITY_GLSL
#define SHADEL_PATH_VISIBILITY_GLSL
#include "raytracing/rt_effects.glsl"

struct PathHit {
    bool hit;
    uint instance;
    uint primitive;
    vec2 bary;
    bool frontFace;
};

// Whether the candidate triangle stops the ray whose coin stream is `coin`.
bool candidateStops(FrameConstants f, RtFrame rt, rayQueryEXT q, uint coin) {
    uint instance = uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, false));
    uint primitive = uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, false));
    GpuInstance inst = InstanceBuffer(f.instances).i[instance];
    GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
    if ((mat.flags & (MATERIAL_ALPHA_MASK | MATERIAL_ALPHA_BLEND)) == 0u) return true;
    RtHitSurface h = rtHitSurface(f, rt, instance, primitive,
                                  rayQueryGetIntersectionBarycentricsEXT(q, false), true);
    float alpha = materialBaseAlpha(mat, h.s.uv, vec2(0.0), vec2(0.0));
    if ((mat.flags & MATERIAL_ALPHA_MASK) != 0u) return alpha >= mat.alphaCutoff;
    uint key = rtHash(coin ^ rtHash(instance * 0x9e3779b9u ^ primitive));
    return float(key >> 8u) * (1.0 / 16777216.0) < alpha;
}

PathHit traceClosest(FrameConstants f, RtFrame rt, vec3 origin, vec3 dir, bool alpha, uint coin) {
    rayQueryEXT q;
    rayQueryInitializeEXT(q, rtTlas(rt), alpha ? gl_RayFlagsNoOpaqueEXT : gl_RayFlagsOpaqueEXT,
                          0xFFu, origin, 0.0, dir, 1e30);
    while (rayQueryProceedEXT(q))
        if (candidateStops(f, rt, q, coin)) rayQueryConfirmIntersectionEXT(q);
    PathHit h;
    h.hit = rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionNoneEXT;
    h.instance = h.hit ? uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true)) : 0u;
    h.primitive = h.hit ? uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true)) : 0u;
    h.bary = h.hit ? rayQueryGetIntersectionBarycentricsEXT(q, true) : vec2(0.0);
    h.frontFace = h.hit && rayQueryGetIntersectionFrontFaceEXT(q, true);
    return h;
}

// Whether anything stops the ray before tMax.
bool pathOccluded(FrameConstants f, RtFrame rt, vec3 origin, vec3 dir, float tMax, bool alpha,
                  uint coin) {
    rayQueryEXT q;
    uint flags = gl_RayFlagsTerminateOnFirstHitEXT |
                 (alpha ? gl_RayFlagsNoOpaqueEXT : gl_RayFlagsOpaqueEXT);
    rayQueryInitializeEXT(q, rtTlas(rt), flags, 0xFFu, origin, 0.0, dir, tMax);
    while (rayQueryProceedEXT(q))
        if (candidateStops(f, rt, q, coin)) rayQueryConfirmIntersectionEXT(q);
    return rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionNoneEXT;
}
#endif
