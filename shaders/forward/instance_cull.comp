#version 460
// GPU-driven draw list: one thread per instance, frustum test against the view's planes,
// visible instances append an indexed-indirect command (of the LOD chosen by projected error,
// shaders/culling/cull.glsl) to the list of their material's bucket. firstInstance carries the
// instance id to the vertex shader.
//
// Camera view with --occlusion on runs twice (render/culling/culling.h): phase 1 draws what was
// visible last frame; phase 2, after the depth pyramid of phase 1 is built, tests every
// frustum-visible instance against it, records its visibility for the next frame and appends
// the visible ones phase 1 did not draw.
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "culling/cull.glsl"

layout(local_size_x = 64) in;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t draws;  // DrawIndexedCommand[DRAW_LIST_COUNT * maxDraws]
    uint64_t counts; // uint[DRAW_LIST_COUNT]
    uint maxDraws;
    uint shadowView; // 1: cull against the sun's shadow volume, only casters
    uint phase;      // CullPhase (render/culling/culling.h): 0 = single pass
    uint pad;
    // Phase 2: uint[1 + instances], count then the ids of every instance visible this frame
    // (read back: the decoupled frontend allocates for this set next frame). 0 = none.
    uint64_t visibleList;
} pc;

#define PHASE_SINGLE 0u
#define PHASE_LAST_VISIBLE 1u
#define PHASE_REST 2u

// Where an instance goes, or ~0u when it is culled in this view and phase.
uint drawListOf(FrameConstants f, GpuInstance inst, uint id) {
    GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
    uint list = (mat.flags & MATERIAL_ALPHA_BLEND) != 0u ? DRAW_LIST_BLEND : DRAW_LIST_OPAQUE;
    if (pc.shadowView != 0u && list == DRAW_LIST_BLEND) return ~0u;
    // Instances allocated in the shadel sheet this frame are drawn by the decoupled passes
    // (blended ones through the OIT targets, render/oit).
    if (pc.shadowView == 0u && f.shadel != 0ul &&
        (ShadelObjectBuffer(ShadelFrameRef(f.shadel).s.objects).o[id].flags &
         SHADEL_OBJECT_DECOUPLED) != 0u)
        list = list == DRAW_LIST_OPAQUE ? DRAW_LIST_DECOUPLED : DRAW_LIST_DECOUPLED_BLEND;
    return list;
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    CullingFrame c = CullingFrameRef(f.culling).c;
    uint id = gl_GlobalInvocationID.x;
    uint view = pc.shadowView != 0u ? CULL_VIEW_SHADOW : CULL_VIEW_CAMERA;
    bool inFrustum = false, drawn = false, hidden = false, drawnBefore = false;
    uint triangles = 0u, vertices = 0u;
    if (id < f.instanceCount) {
        GpuInstance inst = InstanceBuffer(f.instances).i[id];
        inFrustum = true;
        for (int p = 0; p < 6; ++p) {
            vec4 plane = pc.shadowView != 0u ? f.shadowPlanes[p] : f.frustumPlanes[p];
            if (outsidePlane(plane, inst.worldMin, inst.worldMax)) inFrustum = false;
        }
        if (inFrustum && pc.shadowView != 0u)
            inFrustum = !shadowCannotReachView(f, c, inst.worldMin, inst.worldMax);
        bool draw = inFrustum;
        if (inFrustum && pc.phase != PHASE_SINGLE) {
            UintBuffer visible = UintBuffer(c.visibility);
            drawnBefore = visible.v[id] != 0u;
            if (pc.phase == PHASE_LAST_VISIBLE) {
                draw = drawnBefore;
            } else {
                hidden = occludedByHiz(f, c, c.hiz, inst.worldMin, inst.worldMax);
                visible.v[id] = hidden ? 0u : 1u;
                if (!hidden && pc.visibleList != 0ul) {
                    UintBuffer list = UintBuffer(pc.visibleList);
                    list.v[1u + atomicAdd(list.v[0], 1u)] = id;
                }
                draw = !hidden && !drawnBefore;
            }
        } else if (!inFrustum && pc.phase == PHASE_REST) {
            UintBuffer(c.visibility).v[id] = 0u;
        }
        uint list = draw ? drawListOf(f, inst, id) : ~0u;
        if (list != ~0u) {
            GpuMesh mesh = MeshBuffer(f.meshes).m[inst.mesh];
            GpuLod lod = selectLod(f, c, inst, mesh);
            uint slot = atomicAdd(UintBuffer(pc.counts).v[list], 1u);
            SHADEL_ASSERT(f, slot < pc.maxDraws, ASSERT_DRAW_OVERFLOW, slot, pc.maxDraws);
            if (slot < pc.maxDraws) {
                DrawIndexedCommand cmd;
                cmd.indexCount = lod.indexCount;
                cmd.instanceCount = 1u;
                cmd.firstIndex = lod.firstIndex;
                // Shadow views draw the proxy set (positions only), except alpha-tested casters,
                // whose depth needs their UVs.
                bool proxy = pc.shadowView != 0u && c.proxyShadows != 0u &&
                             (MaterialBuffer(f.materials).m[inst.material].flags & MATERIAL_ALPHA_MASK) == 0u;
                if (proxy) cmd.firstIndex = lod.proxyFirstIndex;
                vertices = proxy ? lod.proxyUniqueVertices : lod.uniqueVertices;
                cmd.vertexOffset = mesh.vertexOffset;
                cmd.firstInstance = id;
                DrawBuffer(pc.draws).d[list * pc.maxDraws + slot] = cmd;
                // The visibility buffer rebuilds triangles from this
                // (shaders/common/visibility.glsl).
                if (pc.shadowView == 0u) UintBuffer(c.drawnLod).v[id] = lod.firstIndex;
                drawn = true;
                triangles = lod.indexCount / 3u;
            }
        }
    }
    // Per-view counts for the stats, one atomic per subgroup.
    CullStatsRef stats = CullStatsRef(c.stats);
    uint nDrawn = subgroupAdd(drawn ? 1u : 0u);
    uint nTriangles = subgroupAdd(triangles);
    uint nVertices = subgroupAdd(vertices);
    // Phase 2 sees every frustum-visible instance again: count those once, in phase 2 / single.
    uint nFrustum = subgroupAdd(inFrustum && pc.phase != PHASE_LAST_VISIBLE ? 1u : 0u);
    uint nHidden = subgroupAdd(hidden && !drawnBefore ? 1u : 0u);
    uint nBefore = subgroupAdd(drawn && pc.phase == PHASE_LAST_VISIBLE ? 1u : 0u);
    if (subgroupElect()) {
        if (nDrawn != 0u) atomicAdd(stats.s.instancesDrawn[view], nDrawn);
        if (nTriangles != 0u) atomicAdd(stats.s.trianglesDrawn[view], nTriangles);
        if (nVertices != 0u) atomicAdd(stats.s.verticesDrawn[view], nVertices);
        if (nFrustum != 0u) atomicAdd(stats.s.frustumVisible[view], nFrustum);
        if (nHidden != 0u) atomicAdd(stats.s.occlusionCulled, nHidden);
        if (nBefore != 0u) atomicAdd(stats.s.drawnLastFrameVisible, nBefore);
    }
}
