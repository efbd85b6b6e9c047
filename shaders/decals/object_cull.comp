#version 460
// Decal culling, coarse per-object half (render/decals): one invocation per instance, every
// decal meeting the camera frustum tested against the instance's world bounds, in decal order,
// into the instance's list. Shadel shading narrows the list to each shadel's point
// (decals/decals.glsl, useShadelDecalList), so shadels of objects no decal meets test nothing
// and the others test only the few decals their object meets.
#include "decals/decal_cull.glsl"

layout(local_size_x = 64) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    DecalFrame df = DecalFrameRef(f.decals).d;
    uint instance = gl_GlobalInvocationID.x;
    if (instance >= df.instanceCount) return;
    DecalRangeBuffer ranges = DecalRangeBuffer(df.objectRanges);
    GpuInstance inst = InstanceBuffer(f.instances).i[instance];
    // Forward-only meshes have no shadels; their pixels take the tile lists.
    if (MeshBuffer(f.meshes).m[inst.mesh].shadelMesh == 0xFFFFFFFFu) {
        ranges.r[instance] = uvec2(0u);
        return;
    }
    DecalBuffer decals = DecalBuffer(df.decals);
    UintBuffer frustumDecals = UintBuffer(df.frustumDecals);
    uint n = 0u;
    for (uint i = 0u; i < df.frustumDecalCount; ++i)
        if (decalMeetsBox(decals.d[frustumDecals.v[i]], inst.worldMin, inst.worldMax)) n++;
    if (n == 0u) {
        ranges.r[instance] = uvec2(0u);
        return;
    }
    DecalCountersRef counters = DecalCountersRef(df.counters);
    atomicAdd(counters.c.objectPairs, n);
    uint first = atomicAdd(counters.c.poolEntries, n);
    if (first + n > df.poolCapacity) { // conservative: the chunks test every frustum decal
        ranges.r[instance] = uvec2(0u, DECAL_OBJECT_ALL);
        return;
    }
    UintBuffer entries = UintBuffer(df.entries);
    uint w = 0u;
    for (uint i = 0u; i < df.frustumDecalCount; ++i) {
        uint index = frustumDecals.v[i];
        if (decalMeetsBox(decals.d[index], inst.worldMin, inst.worldMax)) entries.v[first + w++] = index;
    }
    ranges.r[instance] = uvec2(first, n);
}
