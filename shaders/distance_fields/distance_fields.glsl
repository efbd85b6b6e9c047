// Sphere tracing through mesh distance fields in the 3-D atlas (render/distance_fields).
#ifndef SHADEL_DISTANCE_FIELDS_GLSL
#define SHADEL_DISTANCE_FIELDS_GLSL
#include "common/bindless.glsl"
#include "distance_fields/df_types.h"

layout(buffer_reference, scalar) readonly buffer DistanceFieldFrameRef { DistanceFieldFrame d; };
layout(buffer_reference, scalar) readonly buffer DfAtlas { float v[]; };
layout(buffer_reference, scalar) readonly buffer DfMeshes { GpuDistanceFieldMesh m[]; };
layout(buffer_reference, scalar) readonly buffer DfInstances { GpuDistanceFieldInstance i[]; };

float dfVoxel(DistanceFieldFrame df, uvec3 v) {
    return DfAtlas(df.atlas).v[(v.z * df.atlasSize.y + v.y) * df.atlasSize.x + v.x];
}

// Trilinear distance (object-space metres) at an object-space point inside the field's box.
float dfSample(DistanceFieldFrame df, GpuDistanceFieldMesh m, vec3 p) {
    vec3 v = clamp((p - m.origin) / m.voxelSize, vec3(0.0), vec3(m.resolution) - 1.0001);
    uvec3 i = uvec3(floor(v));
    vec3 t = v - vec3(i);
    uvec3 a = m.atlasOrigin + i;
    float c000 = dfVoxel(df, a), c100 = dfVoxel(df, a + uvec3(1, 0, 0));
    float c010 = dfVoxel(df, a + uvec3(0, 1, 0)), c110 = dfVoxel(df, a + uvec3(1, 1, 0));
    float c001 = dfVoxel(df, a + uvec3(0, 0, 1)), c101 = dfVoxel(df, a + uvec3(1, 0, 1));
    float c011 = dfVoxel(df, a + uvec3(0, 1, 1)), c111 = dfVoxel(df, a + uvec3(1, 1, 1));
    return mix(mix(mix(c000, c100, t.x), mix(c010, c110, t.x), t.y),
               mix(mix(c001, c101, t.x), mix(c011, c111, t.x), t.y), t.z);
}

// Ray / box overlap as [tNear, tFar] (empty when tNear > tFar).
vec2 dfRayBox(vec3 o, vec3 invDir, vec3 lo, vec3 hi) {
    vec3 a = (lo - o) * invDir, b = (hi - o) * invDir;
    vec3 mn = min(a, b), mx = max(a, b);
    return vec2(max(max(mn.x, mn.y), mn.z), min(min(mx.x, mx.y), mx.z));
}

// Soft visibility of a light along `dir` from `o` (world). Penumbrae are centred on the
// geometric shadow edge: the ray may pass into an occluder (negative distances, small steps),
// r = min(k d / t) runs from -1 (deep inside) to 1 (clear), and visibility is a smooth ramp of r
// that is 0.5 at the edge (Quilez's improved soft shadows), as the shadow map's PCF is centred.
// Each instance is traced only inside its own field's box; the smallest r over them counts.
float dfSoftShadow(DistanceFieldFrame df, vec3 o, vec3 dir, float maxDistance) {
    float r = 1.0;
    DfInstances instances = DfInstances(df.instances);
    vec3 invDir = 1.0 / (dir + vec3(1e-12));
    for (uint n = 0u; n < df.instanceCount && r > -1.0; ++n) {
        GpuDistanceFieldInstance inst = instances.i[n];
        vec2 span = dfRayBox(o, invDir, inst.worldMin, inst.worldMax);
        if (span.x > min(span.y, maxDistance) || span.y < 0.0) continue;
        GpuDistanceFieldMesh m = DfMeshes(df.meshes).m[inst.mesh];
        if (m.valid == 0u) continue;
        vec3 oo = (inst.worldToObject * vec4(o, 1.0)).xyz;
        vec3 od = normalize(mat3(inst.worldToObject) * dir);
        vec3 hi = m.origin + vec3(m.resolution - 1u) * m.voxelSize;
        vec2 box = dfRayBox(oo, 1.0 / (od + vec3(1e-12)), m.origin, hi);
        float t = max(box.x, 0.0);
        float tEnd = min(box.y, maxDistance / inst.scale);
        float minStep = m.voxelSize * 0.1;
        for (int step = 0; step < 96 && t < tEnd; ++step) {
            float d = dfSample(df, m, oo + od * t);
            r = min(r, df.softness * d / max(t, 1e-3)); // scale cancels in d / t
            if (r <= -1.0) break;
            t += clamp(d, minStep, m.voxelSize * 4.0);
        }
    }
    r = max(r, -1.0);
    return 0.25 * (1.0 + r) * (1.0 + r) * (2.0 - r);
}

// The instances whose box, grown by `radius`, holds `p`: what AO samples around p can meet.
#define DF_NEAR_MAX 32
struct DfNearby {
    uint count;
    uint index[DF_NEAR_MAX];
};

DfNearby dfGatherNearby(DistanceFieldFrame df, vec3 p, float radius) {
    DfNearby near;
    near.count = 0u;
    DfInstances instances = DfInstances(df.instances);
    for (uint n = 0u; n < df.instanceCount && near.count < DF_NEAR_MAX; ++n) {
        GpuDistanceFieldInstance inst = instances.i[n];
        if (any(lessThan(p, inst.worldMin - radius)) || any(greaterThan(p, inst.worldMax + radius)))
            continue;
        if (DfMeshes(df.meshes).m[inst.mesh].valid == 0u) continue;
        near.index[near.count++] = n;
    }
    return near;
}

// Distance (world metres) from `p` to the nearest surface of the gathered instances (beyond a
// field's box, the distance to the box plus the field at its edge: a lower bound), at most
// `radius`.
float dfNearest(DistanceFieldFrame df, DfNearby near, vec3 p, float radius) {
    float nearest = radius;
    DfInstances instances = DfInstances(df.instances);
    for (uint k = 0u; k < near.count; ++k) {
        GpuDistanceFieldInstance inst = instances.i[near.index[k]];
        GpuDistanceFieldMesh m = DfMeshes(df.meshes).m[inst.mesh];
        vec3 po = (inst.worldToObject * vec4(p, 1.0)).xyz;
        vec3 hi = m.origin + vec3(m.resolution - 1u) * m.voxelSize;
        vec3 outside = max(max(m.origin - po, po - hi), vec3(0.0));
        float d = dfSample(df, m, po) + length(outside);
        nearest = min(nearest, d * inst.scale);
    }
    return nearest;
}

// Ambient occlusion from the fields: how much of a few cones around the normal is filled at
// growing distances (1 = open). The instances near the point are gathered once.
float dfAmbientOcclusion(DistanceFieldFrame df, vec3 p, vec3 n) {
    const float firstStep = 0.12;
    const int steps = 4;
    // A sample s from p is within s of what it can meet: gather within twice the last s.
    DfNearby near = dfGatherNearby(df, p, 2.0 * firstStep * float(1 << (steps - 1)));
    vec3 t = normalize(abs(n.y) < 0.9 ? cross(n, vec3(0, 1, 0)) : cross(n, vec3(1, 0, 0)));
    vec3 b = cross(n, t);
    const vec2 dirs[4] = vec2[4](vec2(1, 0), vec2(0, 1), vec2(-1, 0), vec2(0, -1));
    float occlusion = 0.0, total = 0.0;
    for (int c = 0; c < 5; ++c) {
        vec3 dir = c == 0 ? n : normalize(n + 0.9 * (t * dirs[c - 1].x + b * dirs[c - 1].y));
        // An open flat surface leaves a sample s along `dir` at s cos(theta) from any surface:
        // only what is nearer than that occludes.
        float open = dot(dir, n);
        float s = firstStep;
        for (int k = 0; k < steps; ++k, s *= 2.0) {
            float d = dfNearest(df, near, p + dir * s, s);
            float w = 1.0 / float(k + 1);
            occlusion += w * clamp((s * open - d) / (s * open), 0.0, 1.0);
            total += w;
        }
    }
    return clamp(1.0 - 1.5 * occlusion / total, 0.0, 1.0);
}
#endif
