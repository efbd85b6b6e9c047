#version 460
// GPU-driven draw lists: one thread per instance, tested against every view in one dispatch
// (render/culling/culling.h): the camera, the sun's whole-scene shadow volume and, with
// --shadow-culling per-view, each sun cascade's box and each shadow-casting spot's frustum.
// A visible instance appends an indexed-indirect command (of the LOD chosen by projected error
// from the camera, shaders/culling/cull.glsl) to that view's list: the camera's per material
// bucket, the shadow views' opaque casters. firstInstance carries the instance id to the vertex
// shader.
//
// Camera view with --occlusion on runs twice (render/culling/culling.h): phase 1 (this dispatch,
// with the shadow views) draws what was visible last frame; phase 2, after the depth pyramid of
// phase 1 is built, tests every frustum-visible instance against it, records its visibility for
// the next frame and appends the visible ones phase 1 did not draw (camera only).
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "culling/cull.glsl"

layout(local_size_x = 64) in;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t draws;  // camera: DrawIndexedCommand[DRAW_CAMERA_SLOTS * maxDraws]
    uint64_t counts; // camera: uint[DRAW_CAMERA_SLOTS]
    uint maxDraws;
    uint shadowViews; // 1: the shadow views too (the sun's and CullingFrame's per-view lists)
    uint phase;       // CullPhase (render/culling/culling.h): 0 = single pass
    uint pad;
    // Phase 2: uint[1 + instances], count then the ids of every instance visible this frame
    // (read back: the decoupled frontend allocates for this set next frame). 0 = none.
    uint64_t visibleList;
    uint64_t sunDraws;  // the sun's whole-scene map: DrawIndexedCommand[DRAW_LIST_COUNT * maxDraws]
    uint64_t sunCounts; // uint[DRAW_LIST_COUNT]
} pc;

layout(buffer_reference, scalar) readonly buffer ShadowCullViewBuffer {
    GpuShadowCullView v[];
};

#define PHASE_SINGLE 0u
#define PHASE_LAST_VISIBLE 1u
#define PHASE_REST 2u

// The camera's list for an instance (its material's bucket), and in it the side the instance
// draws (DRAW_SIDE_*): its slot of DRAW_CAMERA_SLOTS.
uint cameraSlotOf(FrameConstants f, GpuMaterial mat, GpuInstance inst, uint id) {
    uint list = (mat.flags & MATERIAL_ALPHA_BLEND) != 0u ? DRAW_LIST_BLEND : DRAW_LIST_OPAQUE;
    // Instances allocated in the shadel sheet this frame are drawn by the decoupled passes
    // (blended ones through the OIT targets, render/oit).
    if (f.shadel != 0ul && (ShadelObjectBuffer(ShadelFrameRef(f.shadel).s.objects).o[id].flags &
                            SHADEL_OBJECT_DECOUPLED) != 0u)
        list = list == DRAW_LIST_OPAQUE ? DRAW_LIST_DECOUPLED : DRAW_LIST_DECOUPLED_BLEND;
    // Forward opaque surfaces by the pipeline their material needs (render/forward).
    uint features = (mat.flags >> MATERIAL_FEATURES_SHIFT) & MATERIAL_FEATURES_ALL;
    if (list == DRAW_LIST_OPAQUE && features != 0u)
        list = features == MATERIAL_FEATURE_TEXTURES ? DRAW_LIST_OPAQUE_TEXTURED
                                                     : DRAW_LIST_OPAQUE_FEATURED;
    // Single-sided materials cull back faces.
    uint side = (mat.flags & MATERIAL_DOUBLE_SIDED) != 0u ? DRAW_SIDE_BOTH : DRAW_SIDE_FRONT;
    // A mirroring transform turns counter-clockwise triangles clockwise.
    if (determinant(mat3(inst.model)) < 0.0) side += DRAW_SIDE_MIRRORED;
    return list * DRAW_SIDE_COUNT + side;
}

// Appends one command to list `list` of `draws` (maxDraws commands per list); false when full.
bool appendDraw(uint64_t draws, uint64_t counts, uint list, GpuLod lod, bool proxy, GpuMesh mesh,
                uint id, FrameConstants f) {
    uint slot = atomicAdd(UintBuffer(counts).v[list], 1u);
    SHADEL_ASSERT(f, slot < pc.maxDraws, ASSERT_DRAW_OVERFLOW, slot, pc.maxDraws);
    if (slot >= pc.maxDraws) return false;
    DrawIndexedCommand cmd;
    cmd.indexCount = lod.indexCount;
    cmd.instanceCount = 1u;
    cmd.firstIndex = proxy ? lod.proxyFirstIndex : lod.firstIndex;
    cmd.vertexOffset = mesh.vertexOffset;
    cmd.firstInstance = id;
    DrawBuffer(draws).d[list * pc.maxDraws + slot] = cmd;
    return true;
}

// One view's counts for the stats, one atomic per subgroup and counter.
void countView(CullStatsRef stats, uint view, bool inFrustum, bool drawn, uint triangles,
               uint vertices) {
    uint nDrawn = subgroupAdd(drawn ? 1u : 0u);
    uint nTriangles = subgroupAdd(triangles);
    uint nVertices = subgroupAdd(vertices);
    uint nFrustum = subgroupAdd(inFrustum ? 1u : 0u);
    if (subgroupElect()) {
        if (nDrawn != 0u) atomicAdd(stats.s.instancesDrawn[view], nDrawn);
        if (nTriangles != 0u) atomicAdd(stats.s.trianglesDrawn[view], nTriangles);
        if (nVertices != 0u) atomicAdd(stats.s.verticesDrawn[view], nVertices);
        if (nFrustum != 0u) atomicAdd(stats.s.frustumVisible[view], nFrustum);
    }
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    CullingFrame c = CullingFrameRef(f.culling).c;
    CullStatsRef stats = CullStatsRef(c.stats);
    uint id = gl_GlobalInvocationID.x;
    bool valid = id < f.instanceCount;
    GpuInstance inst;
    GpuMesh mesh;
    GpuMaterial mat;
    if (valid) {
        inst = InstanceBuffer(f.instances).i[id];
        mesh = MeshBuffer(f.meshes).m[inst.mesh];
        mat = MaterialBuffer(f.materials).m[inst.material];
    }
    // The camera's LOD, chosen once: every view draws it, so shadows match what is drawn.
    bool haveLod = false;
    GpuLod lod;

    // ---- The camera.
    bool inFrustum = false, drawn = false, hidden = false, drawnBefore = false;
    uint triangles = 0u, vertices = 0u;
    if (valid) {
        inFrustum = true;
        for (int p = 0; p < 6; ++p)
            if (outsidePlane(f.frustumPlanes[p], inst.worldMin, inst.worldMax)) inFrustum = false;
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
        // Transmissive surfaces are drawn after the opaque scene, from a CPU list
        // (render/transmission): in none of the camera's lists, so not in the prepass either.
        if ((mat.flags & MATERIAL_TRANSMISSION) != 0u) draw = false;
        if (draw) {
            lod = selectLod(f, c, inst, mesh);
            haveLod = true;
            if (appendDraw(pc.draws, pc.counts, cameraSlotOf(f, mat, inst, id), lod, false, mesh, id,
                           f)) {
                drawn = true;
                triangles = lod.indexCount / 3u;
                vertices = lod.uniqueVertices;
            }
        }
    }
    {
        // Phase 2 sees every frustum-visible instance again: count those once, in phase 2 /
        // single.
        countView(stats, CULL_VIEW_CAMERA, inFrustum && pc.phase != PHASE_LAST_VISIBLE, drawn,
                  triangles, vertices);
        uint nHidden = subgroupAdd(hidden && !drawnBefore ? 1u : 0u);
        uint nBefore = subgroupAdd(drawn && pc.phase == PHASE_LAST_VISIBLE ? 1u : 0u);
        if (subgroupElect()) {
            if (nHidden != 0u) atomicAdd(stats.s.occlusionCulled, nHidden);
            if (nBefore != 0u) atomicAdd(stats.s.drawnLastFrameVisible, nBefore);
        }
    }
    if (pc.shadowViews == 0u) return; // uniform: phase 2 is the camera's alone

    // ---- The shadow views: opaque casters only (blended surfaces cast no shadow). Shadow
    // views draw the proxy set (positions only), except alpha-tested casters, whose depth needs
    // their UVs.
    bool caster = valid && (mat.flags & MATERIAL_ALPHA_BLEND) == 0u;
    bool proxy = c.proxyShadows != 0u && (mat.flags & MATERIAL_ALPHA_MASK) == 0u;
    uint casterTriangles = 0u, casterVertices = 0u;
    // A caster matters to the sun's views only if its shadow can reach the camera's frustum.
    bool reachesCamera = caster && !shadowCannotReachView(f, c, inst.worldMin, inst.worldMax);
    // A sun map to keep (render/lighting/sun_shadow_cache.h) holds every caster in the sun's
    // volume; a kept one is not redrawn, and its list is not built.
    bool sunCaster = c.sunList == SUN_LIST_ALL      ? caster
                     : c.sunList == SUN_LIST_CAMERA ? reachesCamera
                                                    : false;
    if (sunCaster || (caster && c.shadowViewCount != 0u)) {
        if (!haveLod) lod = selectLod(f, c, inst, mesh);
        casterTriangles = lod.indexCount / 3u;
        casterVertices = proxy ? lod.proxyUniqueVertices : lod.uniqueVertices;
    }

    // The sun's whole-scene volume.
    inFrustum = sunCaster;
    for (int p = 0; p < 6 && inFrustum; ++p)
        if (outsidePlane(f.shadowPlanes[p], inst.worldMin, inst.worldMax)) inFrustum = false;
    drawn = inFrustum &&
            appendDraw(pc.sunDraws, pc.sunCounts, DRAW_LIST_OPAQUE, lod, proxy, mesh, id, f);
    countView(stats, CULL_VIEW_SHADOW, inFrustum, drawn, drawn ? casterTriangles : 0u,
              drawn ? casterVertices : 0u);

    // Each cascade's box and each spot's frustum, into the view's own list.
    for (uint k = 0u; k < c.shadowViewCount; ++k) {
        GpuShadowCullView view = ShadowCullViewBuffer(c.shadowViews).v[k];
        inFrustum = view.kind == CULL_SHADOW_VIEW_CASCADE ? reachesCamera : caster;
        for (int p = 0; p < 5 && inFrustum; ++p)
            if (outsidePlane(view.planes[p], inst.worldMin, inst.worldMax)) inFrustum = false;
        drawn = inFrustum && appendDraw(c.shadowViewDraws, c.shadowViewCounts, view.list, lod,
                                        proxy, mesh, id, f);
        countView(stats, view.view, inFrustum, drawn, drawn ? casterTriangles : 0u,
                  drawn ? casterVertices : 0u);
    }
}
