#version 460
// The classify pass of the shadel path's feature spectra (chunk_spectra.glsl,
// render/lighting/feature_spectra.h): one invocation per queued chunk, 64 chunks a workgroup.
// Each invocation carries the chunk over when it can, else builds the chunk's world box from
// the positions its shadels are lit at (as the shading rebuilds them), culls the lights
// against it (the light grid's candidates, then the blockers), keeps the list in light order
// for the shading permutations, and bins the chunk by the features the list and its material
// need.
// Why one invocation per chunk: it was a permutation of the shading itself (one 8x8 workgroup
// per chunk, the culling shared by its 64 invocations through shared memory and barriers),
// and on builtin:lights at 1280x720 that took 105-150 ms of a ~600 ms frame on lavapipe, where a
// workgroup per chunk and each barrier cost far more than the tests: 29 ms was the bare
// workgroup per chunk (~16,000 a frame), ~30 the shared bit set and its barriers. Here nothing
// is shared, no barrier is needed, and a chunk's serial walk (its 64 positions, ~100 candidate
// lights, ~14 kept) runs beside 63 others'.
#include "shadel/shade_chunk.glsl"
#include "common/dispatch_2d.h"
#include "common/lighting.glsl"
#include "lighting/light_cull.glsl"
#include "lighting/light_grid.glsl" // the query only (no LIGHT_GRID_LIST)
#include "lighting/spectra.glsl"
#include "common/ordered_float.glsl"

layout(local_size_x = 64) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

// The lights a chunk keeps here, in light order; a chunk with more (rare: a large box among many
// lights) has its list written by a pass of its own (chunk_long_lists.comp, the same list: its
// walks would cost every chunk here, ~5 ms at 1280x720 on builtin:lights, as code the SIMD
// groups carry).
#define CLASSIFY_MAX_LIGHTS 64u
uint gLights[CLASSIFY_MAX_LIGHTS];
uint gMasks[CLASSIFY_MAX_LIGHTS];

// Inserts `light` into the first n entries of gLights (sorted) unless it is there already: a
// light listed in several of the query's cells is kept once. False when the list is full. The
// grid lists each source in light order, so the search from the end is short.
bool insertLight(inout uint n, uint light) {
    uint at = n;
    while (at > 0u && gLights[at - 1u] > light) at--;
    if (at > 0u && gLights[at - 1u] == light) return true;
    if (n == CLASSIFY_MAX_LIGHTS) return false;
    for (uint i = n; i > at; --i) gLights[i] = gLights[i - 1u];
    gLights[at] = light;
    n++;
    return true;
}

// The lights chunkKeepsLight keeps for the box, into gLights: the light grid's candidates, or
// every light when the grid cannot answer (as shade.comp's cullChunkLights). `tested`: the
// candidates tested. False when they do not fit (chunk_long_lists.comp then walks them).
bool cullChunk(FrameConstants f, LightingFrame lf, vec3 boxMin, vec3 boxMax, vec3 corners[8],
               out uint count, out uint tested) {
    LightBuffer lights = LightBuffer(f.lights);
    LightGridCandidates c = lightCandidatesNear(f, lf.lightGrid, boxMin, boxMax);
    tested = c.total;
    count = 0u;
    for (uint s = 0u; s < c.sources; ++s)
        for (uint k = 0u; k < c.lists[s].y; ++k) {
            uint light = lightCandidate(c, s, k);
            if (chunkKeepsLight(lights.l[light], boxMin, boxMax, corners) && !insertLight(count, light))
                return false;
        }
    return true;
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    ShadelCountersRef counters = ShadelCountersRef(s.counters);
    uint group = dispatch2dGroup();
    uint workIndex = group * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
    if (workIndex >= counters.c.shadeDispatch.w) return;
    GpuShadelWork work = ShadelWorkBuffer(s.queue).w[workIndex];
    ShadelObjectRef o = shadelObject(s, work.object);
    // Chunks of objects a changed region meets come to the queue even when reusable (the fill
    // pass cannot tell which of their shadels the change reaches): carried over unless one of
    // their shadels lies in it.
    int carrySlot = (o.v.flags & SHADEL_OBJECT_NEAR_CHANGE) != 0u
                        ? carrySource(s, o, work, f.cameraPosition)
                        : -1;

    // The box of the positions the chunk's shadels are lit at (order-preserving bits, so it is
    // the box the shading's subgroup reduction builds).
    GpuInstance inst = InstanceBuffer(f.instances).i[work.object];
    GpuMesh mesh = MeshBuffer(f.meshes).m[inst.mesh];
    uvec2 size = levelSize(o, work.mip);
    uvec3 lo = uvec3(0xFFFFFFFFu), hi = uvec3(0u);
    bool nearChange = false;
    for (uint i = 0u; i < SHADEL_CHUNK * SHADEL_CHUNK; ++i) {
        uvec2 shadel;
        uint tri;
        if (!chunkShadel(s, o, work, i, shadel, tri)) continue;
        SHADEL_ASSERT(f, tri * 3u < mesh.indexCount, ASSERT_TRIANGLE_ID, tri, mesh.indexCount);
        if (tri * 3u >= mesh.indexCount) continue;
        vec3 world = shadelWorldPosition(f, s, inst, mesh, tri, shadel, size);
        uvec3 bits = orderedFloatBits(world);
        lo = min(lo, bits);
        hi = max(hi, bits);
        if (carrySlot >= 0 && !nearChange) nearChange = inChangedRegion(s, world);
    }
    if (carrySlot >= 0 && !nearChange) { // as carry_over.comp, one invocation for the chunk
        for (uint row = 0u; row < SHADEL_CHUNK; ++row) carryChunkRow(s, uint(carrySlot), work.slot, row);
        carryChunkRecord(s, uint(carrySlot), work.slot);
        return;
    }

    // Spectra need the lighting frame (feature_spectra.h: they exist only with it).
    LightingFrame lf = LightingFrameRef(f.lighting).l;
    SpectraFrame sf = SpectraFrameRef(lf.chunkSpectra).s;
    ChunkListBuffer ranges = ChunkListBuffer(sf.chunkRanges);
    // Without tiled culling every light may reach the chunk (its permutation loops over all).
    if (lf.tiled == 0u) {
        binChunkSpectrum(lf, workIndex, SPECTRUM_ALL);
        return;
    }
    if (hi.x == 0u) { // no shadel to shade: the cheapest mode writes its zeros
        ranges.e[workIndex] = uvec2(0u);
        binChunkSpectrum(lf, workIndex, 0u);
        return;
    }
    vec3 boxMin = orderedBitsFloat(lo), boxMax = orderedBitsFloat(hi);
    vec3 corners[8];
    for (int i = 0; i < 8; ++i) corners[i] = boxCorner(boxMin, boxMax, i);
    uint features = frameFeatures(f, lf);
    if ((o.v.flags & SHADEL_OBJECT_FEATURED_MATERIAL) != 0u) features |= SPECTRUM_MATERIAL;
    uint count, tested;
    LightingCountersRef lc = LightingCountersRef(lf.counters);
    if (!cullChunk(f, lf, boxMin, boxMax, corners, count, tested)) {
        // Left to the long-list pass with its box and the features known so far, which counts
        // the features its lights need; binned here (before the bins' dispatch sizes) to every
        // lighting feature, so that it is shaded right even if its list then overflows the pool
        // and it takes every light (a few dozen chunks a frame).
        uint slot = atomicAdd(UintBuffer(sf.chunkListCount).v[2], 1u);
        Uvec4Buffer(sf.longChunks).v[2u * slot] = uvec4(workIndex, floatBitsToUint(boxMin));
        Uvec4Buffer(sf.longChunks).v[2u * slot + 1u] = uvec4(floatBitsToUint(boxMax), features);
        ranges.e[workIndex] = uvec2(0u, CHUNK_LIST_NONE); // until that pass writes it
        atomicAdd(lc.c.lightGridCandidates, tested);
        appendChunkToBin(sf, workIndex, features | SPECTRUM_ALL_LIGHTING);
        return;
    }

    // Each kept light's blockers against the box: the lights one hides from the whole chunk
    // dropped, the others' masks of blockers to test per shadel; the list's features.
    LightBuffer lights = LightBuffer(f.lights);
    UintBuffer visible = UintBuffer(lf.visibleLights);
    uint kept = 0u;
    bool perPixel = false;
    for (uint i = 0u; i < count; ++i) {
        uint light = gLights[i];
        GpuLight l = lights.l[light];
        uint mask = lightBlockerMask(lf, l, corners, boxMin, boxMax);
        if (mask == LIGHT_INVALID) continue;
        gLights[kept] = light;
        gMasks[kept++] = mask;
        perPixel = perPixel || mask != 0u;
        features |= entryFeatures(lf, l, mask, corners);
        uint bit = 1u << (light & 31u); // lights_visible: most are marked already
        if ((visible.v[light >> 5] & bit) == 0u) atomicOr(visible.v[light >> 5], bit);
    }

    // The list, for the chunk's permutation; one that does not fit the pool leaves the chunk to
    // every light there (chunk_spectra.glsl loadChunkLightList: the same sum, counted).
    uint base = kept == 0u ? 0u : atomicAdd(UintBuffer(sf.chunkListCount).v[0], kept);
    bool fits = base <= sf.chunkListCapacity && kept <= sf.chunkListCapacity - base;
    ranges.e[workIndex] = fits ? uvec2(base, kept) : uvec2(0u, CHUNK_LIST_NONE);
    if (fits) {
        ChunkListBuffer pool = ChunkListBuffer(sf.chunkLists);
        for (uint i = 0u; i < kept; ++i) pool.e[base + i] = uvec2(gLights[i], gMasks[i]);
    } else {
        atomicAdd(UintBuffer(sf.chunkListCount).v[1], 1u);
    }

    if (kept != 0u) atomicAdd(lc.c.lightChunkPairs, kept);
    atomicAdd(lc.c.lightGridCandidates, tested);
    if (count != kept) atomicAdd(lc.c.lightsCulledByBlockers, count - kept);
    if (perPixel) atomicAdd(lc.c.perPixelBlockerChunks, 1u);
    uint cover = fits ? features : features | SPECTRUM_ALL_LIGHTING; // else it takes every light
    countSpectrumFeatures(sf, appendChunkToBin(sf, workIndex, cover), features);
}
