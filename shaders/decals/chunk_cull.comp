#version 460
// Decal culling, shadel half (render/decals): one 8x8 workgroup per chunk of this frame's
// shading queue (the same indirect dispatch as shadel shading). The chunk's world box is that
// of the points its shadels are shaded at, rebuilt as shadel shading rebuilds them
// (shadel/shade.comp); every decal meeting the camera frustum is tested against it, and the
// chunk's lists (one per stage) are what its shading applies (decals/decals.glsl).
#include "decals/decal_cull.glsl"
#include "shadel/shadel.glsl"
#include "common/shadel_bary.h"
#include "common/ordered_float.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

shared uint sBoxMin[3], sBoxMax[3];

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    DecalFrame df = DecalFrameRef(f.decals).d;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    uint tid = gl_LocalInvocationIndex;
    uint workIndex = gl_WorkGroupID.y * 32768u + gl_WorkGroupID.x;
    if (workIndex >= ShadelCountersRef(s.counters).c.shadeDispatch.w || workIndex >= df.chunkCapacity)
        return;
    if (tid < 3u) sBoxMin[tid] = 0xFFFFFFFFu, sBoxMax[tid] = 0u;
    if (tid == 0u) sDecalCount = 0u;
    barrier();
    // This shadel's surface point, as shadel shading finds it (triangle-ID map, barycentrics).
    GpuShadelWork work = ShadelWorkBuffer(s.queue).w[workIndex];
    ShadelObjectRef o = shadelObject(s, work.object);
    uvec2 size = levelSize(o, work.mip);
    uvec2 shadel = uvec2(work.chunk & 0xFFFFu, work.chunk >> 16) * SHADEL_CHUNK +
                   gl_LocalInvocationID.xy - o.v.rect[work.mip].xy * SHADEL_BLOCK;
    uint tri = 0xFFFFu;
    if (all(lessThan(shadel, size))) {
        uint offset = o.v.idMapOffset[work.mip] + shadel.y * size.x + shadel.x;
        tri = (UintBuffer(s.idMaps).v[offset >> 1] >> ((offset & 1u) * 16u)) & 0xFFFFu;
    }
    if (tri != 0xFFFFu) {
        GpuInstance inst = InstanceBuffer(f.instances).i[work.object];
        GpuMesh mesh = MeshBuffer(f.meshes).m[inst.mesh];
        IndexBuffer indices = IndexBuffer(f.indices);
        uint i0 = indices.i[mesh.firstIndex + tri * 3u] + uint(mesh.vertexOffset);
        uint i1 = indices.i[mesh.firstIndex + tri * 3u + 1u] + uint(mesh.vertexOffset);
        uint i2 = indices.i[mesh.firstIndex + tri * 3u + 2u] + uint(mesh.vertexOffset);
        Vec2Buffer uvs = Vec2Buffer(s.shadelUvs);
        vec3 b = shadelBarycentrics(shadelCenterUv(shadel, size), uvs.v[i0], uvs.v[i1], uvs.v[i2]);
        VertexBuffer vb = VertexBuffer(f.vertices);
        vec3 p = shadelInterpolate(b, vb.v[i0].position, vb.v[i1].position, vb.v[i2].position);
        vec3 world = (inst.model * vec4(p, 1.0)).xyz;
        for (int a = 0; a < 3; ++a) {
            atomicMin(sBoxMin[a], orderedFloatBits(world[a]));
            atomicMax(sBoxMax[a], orderedFloatBits(world[a]));
        }
    }
    barrier();
    if (sBoxMax[0] == 0u) { // no shadel to shade
        clearDecalLists(df.chunkRanges, workIndex);
        return;
    }
    vec3 boxMin = vec3(orderedBitsFloat(sBoxMin[0]), orderedBitsFloat(sBoxMin[1]), orderedBitsFloat(sBoxMin[2]));
    vec3 boxMax = vec3(orderedBitsFloat(sBoxMax[0]), orderedBitsFloat(sBoxMax[1]), orderedBitsFloat(sBoxMax[2]));
    DECAL_CULL_LOOP(df, 64u, decalMeetsBox(d, boxMin, boxMax))
    writeDecalLists(df, df.chunkRanges, workIndex, false, 64u);
}
