// What the shading pass (shade.comp) and the spectra's chunk classify
// (lighting/chunk_classify.comp) both need of a queued chunk: its shadels' triangles, the
// position each shadel is lit at, and whether last frame's storage can be carried over.
#ifndef SHADEL_SHADE_CHUNK_GLSL
#define SHADEL_SHADE_CHUNK_GLSL
#include "shadel/shadel.glsl"
#include "common/shadel_bary.h"

// The triangle of a level texel (0xFFFF: none) in the object's triangle-ID map.
uint triangleId(ShadelFrame s, uint offset) {
    uint word = UintBuffer(s.idMaps).v[offset >> 1];
    return (word >> ((offset & 1u) * 16u)) & 0xFFFFu;
}

// The world position shadel `shadel` (inside the level of `size`) of triangle `tri` is lit at:
// its centre's clamped barycentrics, as the shading pass rebuilds it.
vec3 shadelWorldPosition(FrameConstants f, ShadelFrame s, GpuInstance inst, GpuMesh mesh, uint tri,
                         uvec2 shadel, uvec2 size) {
    IndexBuffer indices = IndexBuffer(f.indices);
    uint i0 = indices.i[mesh.firstIndex + tri * 3u] + uint(mesh.vertexOffset);
    uint i1 = indices.i[mesh.firstIndex + tri * 3u + 1u] + uint(mesh.vertexOffset);
    uint i2 = indices.i[mesh.firstIndex + tri * 3u + 2u] + uint(mesh.vertexOffset);
    Vec2Buffer uvs = Vec2Buffer(s.shadelUvs);
    vec3 b = shadelBarycentrics(shadelCenterUv(shadel, size), uvs.v[i0], uvs.v[i1], uvs.v[i2]);
    VertexBuffer vb = VertexBuffer(f.vertices);
    vec3 p = shadelInterpolate(b, vb.v[i0].position, vb.v[i1].position, vb.v[i2].position);
    return (inst.model * vec4(p, 1.0)).xyz;
}

// Shadel i (row order) of a queued chunk: its texel in the object's level and the triangle
// covering it (0xFFFF: none). False when it lies outside the level or no triangle covers it.
bool chunkShadel(ShadelFrame s, ShadelObjectRef o, GpuShadelWork work, uint i, out uvec2 shadel,
                 out uint tri) {
    uvec2 size = levelSize(o, work.mip);
    uvec2 first = uvec2(work.chunk & 0xFFFFu, work.chunk >> 16) * SHADEL_CHUNK;
    shadel = levelShadel(o, work.mip, first + uvec2(i % SHADEL_CHUNK, i / SHADEL_CHUNK));
    tri = all(lessThan(shadel, size))
              ? triangleId(s, o.v.idMapOffset[work.mip] + shadel.y * size.x + shadel.x)
              : 0xFFFFu;
    return tri != 0xFFFFu;
}

// The chunk's centre shadel (row order), where chunkSurfacePoint looks first.
#define CHUNK_CENTRE_SHADEL ((SHADEL_CHUNK / 2u) * (SHADEL_CHUNK + 1u))

// A point of a queued chunk's surface, the same whichever pass asks: the world position its
// centre shadel is lit at or, when no triangle covers that one, its first covered shadel's (row
// order). False when none is covered. The chunk's view record (chunkViewRecord) is taken from it
// by one invocation, so shading needs no box of the chunk, and no barrier, to record it.
bool chunkSurfacePoint(FrameConstants f, ShadelFrame s, GpuShadelWork work, out vec3 p) {
    ShadelObjectRef o = shadelObject(s, work.object);
    for (uint i = 0u; i <= SHADEL_CHUNK * SHADEL_CHUNK; ++i) {
        uvec2 shadel;
        uint tri;
        if (!chunkShadel(s, o, work, i == 0u ? CHUNK_CENTRE_SHADEL : i - 1u, shadel, tri)) continue;
        GpuInstance inst = InstanceBuffer(f.instances).i[work.object];
        p = shadelWorldPosition(f, s, inst, MeshBuffer(f.meshes).m[inst.mesh], tri, shadel,
                                levelSize(o, work.mip));
        return true;
    }
    p = vec3(0.0);
    return false;
}

// Whether a world point lies in a region whose lighting changed this frame (a light or a
// caster that changed: render/shadel/reuse_invalidation.h), capsules a-b of radius a.w.
bool inChangedRegion(ShadelFrame s, vec3 world) {
    Vec4Buffer volumes = Vec4Buffer(s.changedVolumes);
    for (uint i = 0u; i < s.changedVolumeCount; ++i) {
        vec4 a = volumes.v[2u * i];
        vec3 ab = volumes.v[2u * i + 1u].xyz - a.xyz;
        float t = clamp(dot(world - a.xyz, ab) / max(dot(ab, ab), 1e-12), 0.0, 1.0);
        if (isinf(a.w) || distance(world, a.xyz + t * ab) <= a.w) return true;
    }
    return false;
}

// Whether a position one of the chunk's shadels is lit at lies in a changed region: a chunk that
// could be carried over but whose object a changed region meets is shaded only then. One
// invocation walks the chunk's shadels (near_change.comp).
bool chunkTouchesChangedRegion(FrameConstants f, ShadelFrame s, GpuShadelWork work) {
    ShadelObjectRef o = shadelObject(s, work.object);
    GpuInstance inst = InstanceBuffer(f.instances).i[work.object];
    GpuMesh mesh = MeshBuffer(f.meshes).m[inst.mesh];
    uvec2 size = levelSize(o, work.mip);
    for (uint i = 0u; i < SHADEL_CHUNK * SHADEL_CHUNK; ++i) {
        uvec2 shadel;
        uint tri;
        if (!chunkShadel(s, o, work, i, shadel, tri) || tri * 3u >= mesh.indexCount) continue;
        if (inChangedRegion(s, shadelWorldPosition(f, s, inst, mesh, tri, shadel, size))) return true;
    }
    return false;
}

// Preserved layers: a sample computed last frame is still in last frame's storage. Where last frame
// stored this chunk, returns its storage slot then; -1 when the chunk must be shaded: reuse off,
// the object's level changed (reuseLevels, decided on the CPU), this chunk's turn to be refreshed
// (each chunk is reshaded once per refresh period, at its own phase), or its view turned past what
// its specular tolerates (chunkViewTurned).
int carrySource(ShadelFrame s, ShadelObjectRef o, GpuShadelWork work, vec3 camera) {
    if (s.reuse == 0u || ((o.v.reuseLevels >> work.mip) & 1u) == 0u) return -1;
    if (shadelRefreshDue(s, work.chunk)) return -1;
    uvec2 sheet = uvec2(work.chunk & 0xFFFFu, work.chunk >> 16) * SHADEL_CHUNK;
    uint block = prevBlockIndex(s, o, work.mip, blockIndex(s, sheet));
    if (block == SHADEL_INVALID) return -1;
    uint bit = chunkBit(sheet);
    uint64_t prevMask = Uint64Buffer(s.prevOccupancy).v[block];
    uint prevBase = UintBuffer(s.prevOffsetMap).v[block];
    if ((prevMask & (1ul << bit)) == 0ul || prevBase == SHADEL_INVALID) return -1;
    uint slot = chunkSlot(prevMask, prevBase, bit);
    return chunkViewTurned(s, o, slot, camera) ? -1 : int(slot);
}
#endif
