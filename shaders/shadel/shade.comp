#version 460
// Shading: one 8x8 workgroup per queued chunk. Each shadel finds its triangle in the object's
// triangle-ID map, rebuilds the surface from the triangle's vertices with clamped barycentrics (and
// the barycentrics one shadel right and down, for derivatives), then runs the same material and
// lighting code as the forward path. Every queued chunk that reaches a pipeline is shaded:
// carry-over decisions were taken before (fill_queue.comp, near_change.comp, or the spectra's
// classify), so no barrier is needed here beyond the chunk light culling's (only in pipelines that
// have it, SHADE_OPTIONAL_CHUNK_LIGHTS).
#include "shadel/shadel.glsl"
#include "shadel/shade_chunk.glsl"
#include "common/dispatch_2d.h"
#extension GL_KHR_shader_subgroup_arithmetic : require
#define SHADEL_LIGHT_LIST_SHARED
#define LIGHT_CULL_ORDERED_APPEND
#define LIGHT_CULL_SUBGROUP_COUNTS_CHUNKS // useSubgroupLightList counts into the chunk statistics
#include "common/lighting.glsl"
#include "lighting/light_cull.glsl"
#define LIGHT_GRID_LIST sLightList
#define LIGHT_GRID_LIST_MAX LIGHT_CHUNK_MAX_LIGHTS
#include "lighting/light_grid.glsl"
#include "lighting/light_debug.glsl"
#include "lighting/chunk_spectra.glsl"
#include "common/shadel_bary.h"
// Without spectra the shading pass runs one pipeline per shading class (fill_queue.comp), each
// over its class's list, with what its class does not use compiled out (kMaterialFeatures,
// common/material.glsl; the supersampling, prefilter.glsl). On CPU devices a SIMD group runs
// the code of a branch none of its lanes takes, so unused material features cost every shadel.
layout(constant_id = SHADE_QUEUE_CONSTANT_ID) const uint kShadeQueue = SHADE_QUEUE_ALL;
layout(constant_id = SHADE_OPTIONAL_CONSTANT_ID) const uint kShadeOptional = SHADE_OPTIONAL_ALL;
#define SHADE_HAS(feature) ((kShadeOptional & (feature)) != 0u)
#include "shadel/prefilter.glsl" // reads kShadeQueue
#define DEBUG_LINES_WORKGROUP_BOX
#include "debug/debug_lines.glsl"
#include "raytracing/rt_apply.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

void storeLayers(ShadelFrame s, uint index, vec4 radiance, vec4 material) {
    storeRadiance(s.layers[SHADEL_LAYER_RADIANCE], index, radiance);
    storeMaterial(s.layers[SHADEL_LAYER_MATERIAL], index, material);
}

// The chunk's world box from its shading invocations' positions, with one barrier: each
// subgroup reduces its lanes (subgroupMin/Max of the order-preserving bits, so the box is the
// one per-invocation shared atomics built) and its first lane stores the result; after the
// barrier every invocation reduces the subgroups'. On lavapipe (8-wide SIMD, where each shared
// atomic and barrier is costly) this replaced 6 shared atomics per invocation and two barriers.
// False when no invocation shades. Also resets sAppendCount for the light list (before the
// barrier). Call in uniform control flow.
shared uvec3 sSubgroupBoxMin[SHADEL_CHUNK * SHADEL_CHUNK];
shared uvec3 sSubgroupBoxMax[SHADEL_CHUNK * SHADEL_CHUNK];
bool chunkBox(bool shading, vec3 p, out vec3 boxMin, out vec3 boxMax) {
    uvec3 lo, hi;
    subgroupBoxBits(shading, p, lo, hi);
    if (subgroupElect()) {
        sSubgroupBoxMin[gl_SubgroupID] = lo;
        sSubgroupBoxMax[gl_SubgroupID] = hi;
    }
    if (gl_LocalInvocationIndex == 0u) sAppendCount = 0u;
    barrier();
    for (uint g = 0u; g < gl_NumSubgroups; ++g) {
        lo = min(lo, sSubgroupBoxMin[g]);
        hi = max(hi, sSubgroupBoxMax[g]);
    }
    boxMin = orderedBitsFloat(lo);
    boxMax = orderedBitsFloat(hi);
    return hi.x != 0u;
}

// Light culling per chunk (render/lighting): shading here is not in screen space, so the
// chunk's own world-space box (the positions its 64 shadels are lit at) is the culling volume.
// It is computed here, in the shading workgroup, from positions shading rebuilds anyway: culling
// per block would need a pass before this one rebuilding every marked chunk's positions (or
// per-block bounds baked per MIP), and gives longer lists. Measured on builtin:lights at
// 640x360 (lavapipe, reuse off): chunk boxes kept 158,705 (light, chunk) pairs, 27 per chunk,
// and shading took 3.2 s; the same in-workgroup culling against the object's world box (an
// upper bound of any block's) kept 347,142 pairs and took 7.9 s; no culling took ~50 s. Blocks
// lie between the two, so per chunk it is. The list goes to shared memory in light order;
// blockers are classified against the box as for screen tiles. Call in uniform control flow;
// `shading`: this invocation shades a shadel at p.
void cullChunkLights(FrameConstants f, bool shading, vec3 p) {
    LightingFrame lf = LightingFrameRef(f.lighting).l;
    uint tid = gl_LocalInvocationIndex;
    const uint threads = SHADEL_CHUNK * SHADEL_CHUNK;
    // The light grid's bit set is cleared under the box's barrier (no barrier of its own).
    lightGridMaskClearUnsynced(f, lf.lightGrid, threads);
    vec3 boxMin, boxMax;
    bool hasBox = chunkBox(shading, p, boxMin, boxMax);
    gLightListMode = LIGHT_LIST_SHARED;
    if (!hasBox) { // no shadel to shade
        if (tid == 0u) sLightListCount = 0u;
        barrier(); // (as at the end)
        return;
    }
    vec3 corners[8];
    for (int i = 0; i < 8; ++i) corners[i] = boxCorner(boxMin, boxMax, i);
    LightBuffer lights = LightBuffer(f.lights);
    // The lights near the box from the light grid; without it (or for a box larger than the
    // grid's cells), every light. The same list either way.
    bool gridded = gridChunkLights(f, lf.lightGrid, boxMin, boxMax, corners, threads);
    if (!gridded) {
        for (uint base = 0u; base < f.lightCount; base += threads) {
            uint index = base + tid;
            bool keep = false;
            if (index < f.lightCount) {
                keep = chunkKeepsLight(lights.l[index], boxMin, boxMax, corners);
            }
            uint slot = orderedAppend(keep);
            if (slot < LIGHT_CHUNK_MAX_LIGHTS) sLightList[slot] = uvec2(index, 0u);
        }
        barrier(); // the entries were written by other invocations
    }
    // One invocation finishes the list (the grid's compaction ran on it too): each light's
    // blockers against the box, the lights they hide from the whole chunk dropped (the rest
    // moved up in order), and the counts. A chunk keeps a few lights; walking them costs less
    // than the barrier a parallel pass needs (lavapipe runs invocations in turn).
    if (tid == 0u) {
        uint appended = sAppendCount; // lights kept, before the list's capacity
        uint count = min(appended, LIGHT_CHUNK_MAX_LIGHTS);
        uint kept = 0u;
        bool perPixel = false;
        for (uint i = 0u; i < count; ++i) {
            uint light = sLightList[i].x;
            GpuLight l = lights.l[light];
            uint mask = lightBlockerMask(lf, l, corners, boxMin, boxMax);
            if (mask == LIGHT_INVALID) continue;
            sLightList[kept++] = uvec2(light, mask); // (kept <= i)
            perPixel = perPixel || mask != 0u;
            atomicOr(UintBuffer(lf.visibleLights).v[light >> 5], 1u << (light & 31u));
        }
        sLightListCount = kept;
        LightingCountersRef counters = LightingCountersRef(lf.counters);
        atomicAdd(counters.c.lightChunkPairs, kept);
        atomicAdd(counters.c.lightGridCandidates, gridded ? sGridCandidates : f.lightCount);
        atomicAdd(counters.c.lightsCulledByBlockers, count - kept);
        if (perPixel) atomicAdd(counters.c.perPixelBlockerChunks, 1u);
        if (appended > LIGHT_CHUNK_MAX_LIGHTS) atomicAdd(counters.c.chunksOverflowed, 1u);
    }
    barrier(); // the shading reads the list with every invocation
}

// Reuse: records where the chunk is seen from as it is shaded (a point of its surface and the
// direction to the camera), so fill_queue.comp reshades it once the view turned too far for its
// specular (chunkViewTurned). The centre shadel's invocation records it, from its own position
// or, when it shades nothing, the chunk's first covered shadel's (chunkSurfacePoint): a box of
// the chunk's shadels would take the workgroup's barrier, and on lavapipe a shader with any
// barrier runs each SIMD group as a coroutine, which cost builtin:default's shading (1280x720,
// reuse on) a quarter of its time. Any control flow; `shading`: this invocation shades a shadel
// at `position`.
void recordChunkView(FrameConstants f, ShadelFrame s, GpuShadelWork work, bool shading,
                     vec3 position) {
    if (s.reuse == 0u || gl_LocalInvocationIndex != CHUNK_CENTRE_SHADEL) return;
    vec3 point = position;
    bool seen = shading || chunkSurfacePoint(f, s, work, point);
    Uvec4Buffer(s.chunkViews).v[work.slot] = chunkViewRecord(seen, point, f.cameraPosition);
}

// The decal stats of this shadel's list (useShadelDecalList): (decal, shadel) pairs, and the
// decals kept marked visible, one atomic per subgroup. Any control flow.
void countShadelDecals(FrameConstants f, uint object, uint pairs) {
    uint kept = 0u;
    for (uint st = 0u; st < DECAL_STAGES; ++st) kept |= gDecalShadelList ? gDecalStageMask[st] : 0u;
    pairs = subgroupAdd(pairs);
    kept = subgroupOr(kept);
    if (!subgroupElect() || pairs == 0u) return;
    DecalFrame df = DecalFrameRef(f.decals).d;
    atomicAdd(DecalCountersRef(df.counters).c.shadelPairs, pairs);
    uvec2 range = DecalRangeBuffer(df.objectRanges).r[object];
    uint64_t list = df.entries + uint64_t(range.x) * 4ul;
    if (range.y == DECAL_OBJECT_ALL) list = df.frustumDecals, range.y = df.frustumDecalCount;
    for (uint i = 0u; i < range.y; ++i) {
        if (i < 32u && ((kept >> i) & 1u) == 0u) continue; // entries past 32 are always kept
        uint decal = UintBuffer(list).v[i];
        atomicOr(UintBuffer(df.visibleDecals).v[decal >> 5], 1u << (decal & 31u));
    }
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    gTextureFeedback = f.textureFeedback; // texture streaming: the MIPs the shadels want
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    uint group = dispatch2dGroup();
    uint workIndex;
    if (kShadeQueue != SHADE_QUEUE_ALL) {
        uint shadeClass = kShadeQueue - 1u;
        if (group >= ShadelCountersRef(s.counters).c.classDispatch[shadeClass].w) return;
        workIndex = UintBuffer(s.classQueues).v[shadeClass * s.capacityChunks + group];
    } else {
        workIndex = chunkSpectraWorkIndex(f, group);
        if (workIndex >= ShadelCountersRef(s.counters).c.shadeDispatch.w) return;
    }
    GpuShadelWork work = ShadelWorkBuffer(s.queue).w[workIndex];
    ShadelObjectRef o = shadelObject(s, work.object);
    uvec2 local = gl_LocalInvocationID.xy;
    uint outIndex = storageIndex(work.slot, local);
    uvec2 sheetShadel = uvec2(work.chunk & 0xFFFFu, work.chunk >> 16) * SHADEL_CHUNK + local;
    uvec2 size = levelSize(o, work.mip);
    uvec2 shadel = levelShadel(o, work.mip, sheetShadel);
    // Shadels outside the level or in a gutter no filter reads have nothing to shade; they stay
    // in the workgroup until chunk light culling (barriers) is done.
    bool shading = all(lessThan(shadel, size));
    uint tri = shading ? triangleId(s, o.v.idMapOffset[work.mip] + shadel.y * size.x + shadel.x) : 0xFFFFu;
    shading = shading && tri != 0xFFFFu;
    GpuInstance inst = InstanceBuffer(f.instances).i[work.object];
    GpuMesh mesh = MeshBuffer(f.meshes).m[inst.mesh];
    SHADEL_ASSERT(f, !shading || tri * 3u < mesh.indexCount, ASSERT_TRIANGLE_ID, tri, mesh.indexCount);
    if (!shading) tri = 0u; // a valid triangle to read, never shaded
    IndexBuffer indices = IndexBuffer(f.indices);
    uint i0 = indices.i[mesh.firstIndex + tri * 3u] + uint(mesh.vertexOffset);
    uint i1 = indices.i[mesh.firstIndex + tri * 3u + 1u] + uint(mesh.vertexOffset);
    uint i2 = indices.i[mesh.firstIndex + tri * 3u + 2u] + uint(mesh.vertexOffset);
    Vec2Buffer uvs = Vec2Buffer(s.shadelUvs);
    uvec2 clampedShadel = min(shadel, size - 1u);
    ShadelBary bary = shadelBaryWithNeighbours(clampedShadel, size, uvs.v[i0], uvs.v[i1], uvs.v[i2]);

    VertexBuffer vb = VertexBuffer(f.vertices);
    GpuVertex v0 = vb.v[i0], v1 = vb.v[i1], v2 = vb.v[i2];
    vec3 p = shadelInterpolate(bary.center, v0.position, v1.position, v2.position);
    vec3 n = shadelInterpolate(bary.center, v0.normal, v1.normal, v2.normal);
    vec4 tangent = vec4(shadelInterpolate(bary.center, v0.tangent.xyz, v1.tangent.xyz, v2.tangent.xyz), v0.tangent.w);
    // Texture coordinates extrapolate as far as the triangle's own UV box and no further: past
    // a mesh's border (a quad's edge at v = 0) they would read the texture's far side through
    // REPEAT, and the reconstruction blends those gutter shadels into the border pixels.
    vec2 uv = clampToTriangleUv(shadelInterpolate2(bary.center, v0.uv0, v1.uv0, v2.uv0),
                                v0.uv0, v1.uv0, v2.uv0);
    vec2 uvDx = shadelInterpolate2(bary.right, v0.uv0, v1.uv0, v2.uv0) -
                shadelInterpolate2(bary.center, v0.uv0, v1.uv0, v2.uv0);
    vec2 uvDy = shadelInterpolate2(bary.down, v0.uv0, v1.uv0, v2.uv0) -
                shadelInterpolate2(bary.center, v0.uv0, v1.uv0, v2.uv0);
    vec2 uv1 = clampToTriangleUv(shadelInterpolate2(bary.center, v0.uv1, v1.uv1, v2.uv1),
                                 v0.uv1, v1.uv1, v2.uv1);
    vec2 uv1Dx = shadelInterpolate2(bary.right, v0.uv1, v1.uv1, v2.uv1) -
                 shadelInterpolate2(bary.center, v0.uv1, v1.uv1, v2.uv1);
    vec2 uv1Dy = shadelInterpolate2(bary.down, v0.uv1, v1.uv1, v2.uv1) -
                 shadelInterpolate2(bary.center, v0.uv1, v1.uv1, v2.uv1);

    SurfaceInput si;
    si.position = (inst.model * vec4(p, 1.0)).xyz;
    si.normal = normalize(mat3(inst.normalMatrix) * n);
    si.tangent = vec4(mat3(inst.model) * tangent.xyz, tangent.w);
    si.uv = uv;
    si.uvDx = uvDx;
    si.uvDy = uvDy;
    si.uv1 = uv1;
    si.uv1Dx = uv1Dx;
    si.uv1Dy = uv1Dy;
    // With few lights each subgroup culls them for its own shadels (no barrier); else the
    // chunk culls them, or a spectrum's permutation reads the list its classify pass culled.
    // Spectra never cull per subgroup nor per chunk: their permutations compile neither in.
    // Pipelines of renderers that never cull per chunk leave that culling out, with its
    // barriers: on lavapipe a shader with a barrier runs each SIMD group as a coroutine, which
    // cost builtin:default's shading (1280x720) a fifth of its time.
    if (kChunkSpectraPhase == CHUNK_SPECTRA_OFF && f.lighting != 0ul &&
        LightingFrameRef(f.lighting).l.subgroupLists != 0u)
        useSubgroupLightList(f, shading, si.position);
    else if (kChunkSpectraPhase == CHUNK_SPECTRA_SHADE && f.lighting != 0ul &&
             LightingFrameRef(f.lighting).l.tiled != 0u)
        loadChunkLightList(f, workIndex);
    else if (kChunkSpectraPhase == CHUNK_SPECTRA_OFF && f.lighting != 0ul &&
             LightingFrameRef(f.lighting).l.tiled != 0u) {
        SHADEL_ASSERT(f, SHADE_HAS(SHADE_OPTIONAL_CHUNK_LIGHTS), ASSERT_SHADE_PIPELINE,
                      SHADE_OPTIONAL_CHUNK_LIGHTS, kShadeOptional);
        if (SHADE_HAS(SHADE_OPTIONAL_CHUNK_LIGHTS)) cullChunkLights(f, shading, si.position);
    }
    if (SHADE_HAS(SHADE_OPTIONAL_REUSE)) recordChunkView(f, s, work, shading, si.position);
    // --debug-lines chunks: this chunk's world box, coloured by MIP (uniform over the workgroup).
    if (SHADE_HAS(SHADE_OPTIONAL_DEBUG_LINES) && debugLinesOn(f, DEBUG_LINES_CHUNKS))
        debugWorkgroupBox(f, shading, si.position, debugLevelColour(work.mip));
    if (!shading) {
        storeLayers(s, outIndex, vec4(0.0), vec4(0.0));
        return;
    }
    // No rasterizer here: a surface faces the viewer when its normal points at the camera.
    vec3 geometricNormal = normalize(mat3(inst.normalMatrix) *
                                     cross(v1.position - v0.position, v2.position - v0.position));
    si.frontFacing = dot(geometricNormal, f.cameraPosition - si.position) >= 0.0;
    GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
    if (SHADE_HAS(SHADE_OPTIONAL_RT)) // --rt-* (RT cache)
        useRayTracedShadelTerms(f, work.object, shadelCenterUv(shadel, size));
    // Decals: the object's list (render/decals) narrowed to this shadel's point, applied inside
    // evaluateMaterial, so each shadel takes them once and every pixel reading it reuses them.
    // Opaque surfaces only, as in forward shading.
    uint decalPairs = SHADE_HAS(SHADE_OPTIONAL_DECALS) && (mat.flags & MATERIAL_ALPHA_BLEND) == 0u
                          ? useShadelDecalList(f, work.object, si.position)
                          : 0u;
    if (SHADE_HAS(SHADE_OPTIONAL_DECALS) && f.decals != 0ul)
        countShadelDecals(f, work.object, decalPairs);
    // The shadel's whole footprint, not its centre (prefilter.glsl; --material-samples caps it).
    vec4 material;
    vec3 color = prefilteredShade(f, mat, si, shadelCenterUv(shadel, size), vec2(1.0) / vec2(size),
                                  uvs.v[i0], uvs.v[i1], uvs.v[i2], v0.uv0, v1.uv0, v2.uv0,
                                  s.materialSamples, uvec3(shadel, work.object * 16u + work.mip),
                                  material);
    color = visualizeChunkSpectrum(f, visualizeLighting(f, color));
    storeLayers(s, outIndex, vec4(color, 1.0), material);
}
