// Per-instance culling helpers of the GPU-driven world (render/culling): LOD selection by
// projected error, shadow-caster culling against the camera frustum, and the hierarchical-Z
// occlusion test. Included by shaders/forward/instance_cull.comp.
#ifndef SHADEL_CULL_GLSL
#define SHADEL_CULL_GLSL
#include "common/bindless.glsl"

layout(buffer_reference, scalar) readonly buffer CullingFrameRef {
    CullingFrame c;
};
layout(buffer_reference, scalar) readonly buffer MeshLodBuffer {
    GpuMeshLods m[];
};
layout(buffer_reference, scalar) buffer CullStatsRef {
    GpuCullStats s;
};
layout(buffer_reference, scalar) buffer FloatBuffer {
    float v[];
};

bool outsidePlane(vec4 plane, vec3 bmin, vec3 bmax) {
    vec3 p = vec3(plane.x >= 0.0 ? bmax.x : bmin.x, plane.y >= 0.0 ? bmax.y : bmin.y,
                  plane.z >= 0.0 ? bmax.z : bmin.z);
    return dot(plane.xyz, p) + plane.w < 0.0;
}

// A caster matters only if its shadow can fall inside the camera frustum. Its shadow is the box
// swept along the light until it leaves the scene below its lowest point: the Minkowski sum of
// the box and a segment, whose extent along a plane normal n is the box's plus
// max(0, length * dot(n, light)). Outside any camera plane: culled.
bool shadowCannotReachView(FrameConstants f, CullingFrame c, vec3 bmin, vec3 bmax) {
    float down = -f.sunDirection.y;
    float sweep = down > 1e-3 ? max(bmax.y - c.sceneMinY, 0.0) / down : 1e30;
    for (int p = 0; p < 6; ++p) {
        vec4 plane = f.frustumPlanes[p];
        vec3 corner = vec3(plane.x >= 0.0 ? bmax.x : bmin.x, plane.y >= 0.0 ? bmax.y : bmin.y,
                           plane.z >= 0.0 ? bmax.z : bmin.z);
        float along = dot(plane.xyz, f.sunDirection);
        if (dot(plane.xyz, corner) + plane.w + max(0.0, sweep * along) < 0.0) return true;
    }
    return false;
}

// The coarsest LOD whose object-space error, seen from the camera, stays below the threshold.
// The distance is to the nearest point of the bounding sphere; both views use the camera's
// choice, so shadows match what is drawn.
GpuLod selectLod(FrameConstants f, CullingFrame c, GpuInstance inst, GpuMesh mesh) {
    GpuMeshLods lods = MeshLodBuffer(c.meshLods).m[inst.mesh];
    GpuLod chosen = lods.lod[0];
    if (c.lod == 0u) return chosen;
    vec3 centre = 0.5 * (inst.worldMin + inst.worldMax);
    float radius = 0.5 * length(inst.worldMax - inst.worldMin);
    float distance = max(length(centre - f.cameraPosition) - radius, 1e-3);
    float scale =
        max(length(inst.model[0].xyz), max(length(inst.model[1].xyz), length(inst.model[2].xyz)));
    float pixelsPerUnit = c.lodScale * scale / distance;
    for (uint k = 1u; k < lods.lodCount; ++k) {
        if (lods.lod[k].error * pixelsPerUnit > c.lodErrorPixels) break;
        chosen = lods.lod[k];
    }
    return chosen;
}

// Level k of the depth pyramid starts after levels 0..k-1 (each ceil-halved from the last).
uint hizLevelOffset(uvec2 size0, uint level, out uvec2 size) {
    uint offset = 0u;
    size = size0;
    for (uint k = 0u; k < level; ++k) {
        offset += size.x * size.y;
        size = max((size + 1u) / 2u, uvec2(1u));
    }
    return offset;
}

// Reversed Z: the pyramid keeps the farthest (smallest) depth of what each texel covers. The
// box is hidden when its nearest point lies behind the farthest occluder over its screen rect.
bool occludedByHiz(FrameConstants f, CullingFrame c, uint64_t pyramid, vec3 bmin, vec3 bmax) {
    vec2 lo = vec2(1e30), hi = vec2(-1e30);
    float nearest = 0.0;
    for (uint i = 0u; i < 8u; ++i) {
        vec3 corner = vec3((i & 1u) != 0u ? bmax.x : bmin.x, (i & 2u) != 0u ? bmax.y : bmin.y,
                           (i & 4u) != 0u ? bmax.z : bmin.z);
        vec4 clip = f.viewProj * vec4(corner, 1.0);
        if (clip.w <= 1e-4) return false; // crosses the camera plane: keep
        vec3 ndc = clip.xyz / clip.w;
        lo = min(lo, ndc.xy);
        hi = max(hi, ndc.xy);
        nearest = max(nearest, ndc.z);
    }
    vec2 size = vec2(c.hizSize);
    ivec2 p0 = ivec2(clamp(floor((lo * 0.5 + 0.5) * size), vec2(0.0), size - 1.0));
    ivec2 p1 = ivec2(clamp(floor((hi * 0.5 + 0.5) * size), vec2(0.0), size - 1.0));
    // The finest level where the rect spans at most 2 x 2 texels.
    uint level = 0u;
    while (level + 1u < c.hizLevels &&
           (((p1.x >> level) - (p0.x >> level)) > 1 || ((p1.y >> level) - (p0.y >> level)) > 1))
        level++;
    uvec2 levelSize;
    uint offset = hizLevelOffset(c.hizSize, level, levelSize);
    ivec2 t0 = p0 >> level, t1 = p1 >> level;
    float farthest = 1.0;
    for (int y = t0.y; y <= t1.y; ++y)
        for (int x = t0.x; x <= t1.x; ++x)
            farthest =
                min(farthest, FloatBuffer(pyramid).v[offset + uint(y) * levelSize.x + uint(x)]);
    return nearest < farthest;
}

#endif
