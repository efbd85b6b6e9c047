// Ray-traced lighting terms with rayQueryEXT (render/raytracing), shared by the forward path
// (per pixel, shaders/raytracing/rt_pixel.frag) and the shadel path (per shadel,
// shaders/raytracing/rt_shadels.comp): the sun's visibility (one ray: hard; several jittered
// rays over the sun's disc: soft), ambient occlusion (cosine rays of a fixed length) and one
// bounce of diffuse light (cosine rays; the hit is shaded from its material, the sun with a
// shadow ray, the other lights unshadowed and the ambient term; no recursion).
// The TLAS is reached by its device address (FrameConstants::rt -> RtFrame::tlas), like every
// other resource here.
#ifndef SHADEL_RT_EFFECTS_GLSL
#define SHADEL_RT_EFFECTS_GLSL
#extension GL_EXT_ray_query : require
#include "common/lighting.glsl"
#include "common/vertex.glsl"
#include "raytracing/rt_frame.glsl"

uint rtHash(uint x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

// Sample `i` of a 2-D R2 low-discrepancy sequence, rotated per `seed` (Cranley-Patterson): a
// sample point accumulating over frames walks one sequence (i grows), so it converges faster
// than independent random rays would.
vec2 rtSample2(uint seed, uint i) {
    vec2 rotation = vec2(rtHash(seed), rtHash(seed ^ 0x9e3779b9u)) * (1.0 / 4294967296.0);
    return fract(rotation + float(i) * vec2(0.7548776662466927, 0.5698402909980532));
}

mat3 rtBasis(vec3 n) {
    vec3 t = abs(n.y) < 0.99 ? normalize(cross(vec3(0, 1, 0), n)) : normalize(cross(vec3(1, 0, 0), n));
    return mat3(t, cross(n, t), n);
}

vec3 rtCosineDirection(vec3 n, vec2 u) {
    float r = sqrt(u.x);
    float phi = 6.28318530718 * u.y;
    vec3 local = vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
    return rtBasis(n) * local;
}

// A direction inside the cone of half angle `angle` around `axis` (uniform over the disc).
vec3 rtConeDirection(vec3 axis, float angle, vec2 u) {
    float r = sqrt(u.x) * tan(angle);
    float phi = 6.28318530718 * u.y;
    return normalize(rtBasis(axis) * vec3(r * cos(phi), r * sin(phi), 1.0));
}

accelerationStructureEXT rtTlas(RtFrame rt) { return accelerationStructureEXT(rt.tlas); }

bool rtOccluded(RtFrame rt, vec3 origin, vec3 dir, float tMax) {
    rayQueryEXT q;
    rayQueryInitializeEXT(q, rtTlas(rt), gl_RayFlagsTerminateOnFirstHitEXT | gl_RayFlagsOpaqueEXT,
                          0xFFu, origin, 0.0, dir, tMax);
    while (rayQueryProceedEXT(q)) {}
    return rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionNoneEXT;
}

// Ray origins leave the surface along its geometric normal (on the side the ray goes), by an
// amount that grows with the distance to the camera (the precision of the position does).
vec3 rtOrigin(FrameConstants f, RtFrame rt, vec3 p, vec3 ng, vec3 dir) {
    float offset = rt.normalOffset * max(1.0, length(p - f.cameraPosition));
    return p + (dot(ng, dir) >= 0.0 ? ng : -ng) * offset;
}

void rtCountRays(RtFrame rt, uint rays) {
    if (rays != 0u) atomicAdd(RtCountersRef(rt.counters).c.raysTraced, rays);
}

// Fraction of the sun's disc visible from p (1 ray: 0 or 1).
float rtSunVisibility(FrameConstants f, RtFrame rt, vec3 p, vec3 ng, uint seed, uint sampleBase) {
    vec3 toSun = -f.sunDirection;
    uint rays = max(rt.shadowRays, 1u);
    float visible = 0.0;
    for (uint i = 0u; i < rays; ++i) {
        vec3 dir = rays == 1u ? toSun : rtConeDirection(toSun, rt.sunAngle, rtSample2(seed, sampleBase + i));
        visible += rtOccluded(rt, rtOrigin(f, rt, p, ng, dir), dir, 1e30) ? 0.0 : 1.0;
    }
    rtCountRays(rt, rays);
    return visible / float(rays);
}

// The visibility of every shadow-casting spot from p (RtFrame::spotShadowCount of them), 8 bits
// each by shadow index (rtSpotVisibility in common/lighting.glsl reads them). Spots that cannot
// light p (outside the cone or the range) trace nothing and read 1. One ray to the light: hard;
// with --rt-shadow-rays N > 1 and an emitter (GpuLight::radius > 0), N rays to points of a disc
// of that radius facing p: soft.
uvec4 rtSpotVisibilities(FrameConstants f, RtFrame rt, vec3 p, vec3 ng, uint seed, uint sampleBase) {
    uvec4 packed = uvec4(0xFFFFFFFFu);
    if (rt.spotShadowCount == 0u) return packed;
    LightBuffer lights = LightBuffer(f.lights);
    UintBuffer spotLights = UintBuffer(rt.spotLights);
    uint traced = 0u;
    for (uint k = 0u; k < rt.spotShadowCount; ++k) {
        GpuLight light = lights.l[spotLights.v[k]];
        vec3 toLight = light.position - p;
        float dist = length(toLight);
        vec3 dir = toLight / max(dist, 1e-4);
        if (spotFactor(light, dir) <= 0.0 || (light.range > 0.0 && dist >= light.range)) continue;
        bool soft = rt.shadowRays > 1u && light.radius > 0.0;
        uint rays = soft ? rt.shadowRays : 1u;
        mat3 disc = rtBasis(dir);
        float visible = 0.0;
        for (uint i = 0u; i < rays; ++i) {
            vec3 target = light.position;
            if (soft) {
                vec2 u = rtSample2(seed ^ (k * 0x632be5abu + 0x2545f491u), sampleBase + i);
                float r = light.radius * sqrt(u.x);
                float phi = 6.28318530718 * u.y;
                target += disc[0] * (r * cos(phi)) + disc[1] * (r * sin(phi));
            }
            vec3 d = target - p;
            float len = length(d);
            d /= max(len, 1e-4);
            // The ray stops just short of the emitter (a lamp's own surface at the light is not
            // an occluder of its light).
            visible += rtOccluded(rt, rtOrigin(f, rt, p, ng, d), d, len * 0.999) ? 0.0 : 1.0;
        }
        traced += rays;
        uint q = uint(round(visible / float(rays) * 255.0));
        uint shift = (k & 3u) * 8u;
        packed[k >> 2u] = (packed[k >> 2u] & ~(0xFFu << shift)) | (q << shift);
    }
    rtCountRays(rt, traced);
    return packed;
}

// Spot visibilities `a` moved towards `b` by `w` (each of the 8-bit fields).
uvec4 rtMixSpotVisibilities(uvec4 a, uvec4 b, float w, uint count) {
    uvec4 out_ = a;
    for (uint k = 0u; k < count; ++k) {
        float v = mix(rtSpotVisibility(a, k), rtSpotVisibility(b, k), w);
        uint shift = (k & 3u) * 8u;
        out_[k >> 2u] = (out_[k >> 2u] & ~(0xFFu << shift)) | (uint(round(v * 255.0)) << shift);
    }
    return out_;
}

// Unoccluded fraction of `rays` cosine rays of length aoRadius (1 = open).
float rtAmbientOcclusion(FrameConstants f, RtFrame rt, vec3 p, vec3 n, vec3 ng, uint seed,
                         uint sampleBase, uint rays) {
    float open = 0.0;
    for (uint i = 0u; i < rays; ++i) {
        vec3 dir = rtCosineDirection(n, rtSample2(seed ^ 0x51ed27u, sampleBase + i));
        open += rtOccluded(rt, rtOrigin(f, rt, p, ng, dir), dir, rt.aoRadius) ? 0.0 : 1.0;
    }
    rtCountRays(rt, rays);
    return rays == 0u ? 1.0 : open / float(rays);
}

// The surface of a hit (committed or candidate): the triangle of the LOD the instance's BLAS
// was built from, its attributes interpolated at the barycentrics (no UV derivatives: textures
// are read at their finest MIP), its geometric normal and its material. Shared by every shader
// that shades what a ray hit (here, and the reference path tracer, shaders/reference).
struct RtHitSurface {
    SurfaceInput s;
    vec3 geometricNormal; // unit, on the triangle's front side (not turned toward the ray)
    uint material;
};

RtHitSurface rtHitSurface(FrameConstants f, RtFrame rt, uint instanceId, uint primitive, vec2 bary,
                          bool frontFace) {
    GpuInstance inst = InstanceBuffer(f.instances).i[instanceId];
    GpuMesh mesh = MeshBuffer(f.meshes).m[inst.mesh];
    uint first = UintBuffer(rt.instanceLods).v[instanceId] + primitive * 3u;
    IndexBuffer indices = IndexBuffer(f.indices);
    WorldVertex a = fetchWorldVertex(f, inst, uint(int(indices.i[first]) + mesh.vertexOffset));
    WorldVertex b = fetchWorldVertex(f, inst, uint(int(indices.i[first + 1u]) + mesh.vertexOffset));
    WorldVertex c = fetchWorldVertex(f, inst, uint(int(indices.i[first + 2u]) + mesh.vertexOffset));
    vec3 w = vec3(1.0 - bary.x - bary.y, bary.x, bary.y);
    RtHitSurface h;
    h.s.position = a.position * w.x + b.position * w.y + c.position * w.z;
    h.s.normal = normalize(a.normal * w.x + b.normal * w.y + c.normal * w.z);
    h.s.tangent = a.tangent * w.x + b.tangent * w.y + c.tangent * w.z;
    h.s.uv = a.uv0 * w.x + b.uv0 * w.y + c.uv0 * w.z;
    h.s.uvDx = vec2(0.0);
    h.s.uvDy = vec2(0.0);
    h.s.uv1 = a.uv1 * w.x + b.uv1 * w.y + c.uv1 * w.z;
    h.s.uv1Dx = vec2(0.0);
    h.s.uv1Dy = vec2(0.0);
    h.s.frontFacing = frontFace;
    h.geometricNormal = normalize(cross(b.position - a.position, c.position - a.position));
    if (determinant(mat3(inst.model)) < 0.0) h.geometricNormal = -h.geometricNormal; // mirrored
    h.material = inst.material;
    return h;
}

// Radiance leaving the committed hit of `q` toward the ray's origin (diffuse only).
vec3 rtShadeHit(FrameConstants f, RtFrame rt, uint instanceId, uint primitive, vec2 bary,
                bool frontFace, vec3 rayDir) {
    RtHitSurface hit = rtHitSurface(f, rt, instanceId, primitive, bary, frontFace);
    SurfaceInput s = hit.s;
    GpuMaterial mat = MaterialBuffer(f.materials).m[hit.material];
    MaterialSample m = evaluateMaterial(mat, s);
    if (m.unlit) return m.baseColor;
    vec3 ng = hit.geometricNormal;
    vec3 n = dot(m.normal, rayDir) > 0.0 ? -m.normal : m.normal; // the side the ray sees
    m.metallic = 0.0; // diffuse bounce only
    m.roughness = 1.0;
    vec3 v = -rayDir;
    vec3 color = m.emissive;
    color += environmentIrradiance(f.environment, n) * m.baseColor;
    vec3 toSun = -f.sunDirection;
    if (dot(f.sunColor, f.sunColor) > 0.0 && dot(n, toSun) > 0.0) {
        bool shadowed = rtOccluded(rt, rtOrigin(f, rt, s.position, ng, toSun), toSun, 1e30);
        rtCountRays(rt, 1u);
        if (!shadowed) color += m.baseColor / PI * f.sunColor * dot(n, toSun);
    }
    LightBuffer lights = LightBuffer(f.lights);
    for (uint i = 0u; i < f.lightCount; ++i)
        color += max(evaluateLight(lights.l[i], m, n, v, s.position), vec3(0.0));
    return color;
}

// One bounce of diffuse light: the mean radiance of `rays` cosine rays' hits, i.e. the
// irradiance / pi; the receiver multiplies it by its diffuse albedo. Misses add nothing (the
// ambient term stands for the sky).
vec3 rtIndirectDiffuse(FrameConstants f, RtFrame rt, vec3 p, vec3 n, vec3 ng, uint seed,
                       uint sampleBase, uint rays) {
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < rays; ++i) {
        vec3 dir = rtCosineDirection(n, rtSample2(seed ^ 0xa511e9b3u, sampleBase + i));
        rayQueryEXT q;
        rayQueryInitializeEXT(q, rtTlas(rt), gl_RayFlagsOpaqueEXT, 0xFFu, rtOrigin(f, rt, p, ng, dir),
                              0.0, dir, 1e30);
        while (rayQueryProceedEXT(q)) {}
        if (rayQueryGetIntersectionTypeEXT(q, true) == gl_RayQueryCommittedIntersectionNoneEXT) continue;
        sum += rtShadeHit(f, rt, uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true)),
                          uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true)),
                          rayQueryGetIntersectionBarycentricsEXT(q, true),
                          rayQueryGetIntersectionFrontFaceEXT(q, true), dir);
    }
    rtCountRays(rt, rays);
    return rays == 0u ? vec3(0.0) : sum / float(rays);
}
#endif
