#version 460
// The long lists of the shadel path's feature spectra: the chunks whose kept lights did not fit
// the classify pass's private list (chunk_classify.comp; coarse levels' large chunks among many
// lights, 42 of 16,174 on builtin:lights at 1280x720). One invocation per such chunk writes its
// list, the same one classify would keep (the grid's candidates near its box, each once, in
// light order, less the lights its blockers hide from the whole chunk), into the pool its
// permutation reads. A pass of its own, after the bins' dispatch sizes (chunk_spectra_setup.comp
// sizes this one too), so that the classify's SIMD groups do not carry these walks.
#include "shadel/shade_chunk.glsl"
#include "common/dispatch_2d.h"
#include "common/lighting.glsl"
#include "lighting/light_cull.glsl"
#include "lighting/light_grid.glsl" // the query only (no LIGHT_GRID_LIST)
#include "lighting/spectra.glsl"

// Small workgroups: a few dozen long walks spread over every thread (lavapipe gives each
// thread whole workgroups).
layout(local_size_x = SPECTRA_LONG_LIST_GROUP) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

// The chunk's entries straight into the pool from two walks over the candidates merged in light
// order: each source lists its lights in order, so taking the smallest head and skipping every
// head up to it keeps a light listed by several sources once, and the list is in light order as
// the short ones are. The first walk counts the entries, the statistics and the features they
// need; the second writes them where the count reserved. Returns the chunk's range ((0,
// CHUNK_LIST_NONE) when the pool is full).
uvec2 writeLongList(FrameConstants f, LightingFrame lf, SpectraFrame sf, vec3 boxMin, vec3 boxMax,
                    vec3 corners[8], out uint kept, out uint culledByBlockers, out bool perPixel,
                    inout uint features) {
    LightBuffer lights = LightBuffer(f.lights);
    LightGridCandidates c = lightCandidatesNear(f, lf.lightGrid, boxMin, boxMax);
    UintBuffer visible = UintBuffer(lf.visibleLights);
    ChunkListBuffer pool = ChunkListBuffer(sf.chunkLists);
    uint base = 0u;
    kept = 0u;
    culledByBlockers = 0u;
    perPixel = false;
    for (uint walk = 0u; walk < 2u; ++walk) {
        uint at[LIGHT_GRID_MAX_SOURCES];
        for (uint s = 0u; s < LIGHT_GRID_MAX_SOURCES; ++s) at[s] = 0u;
        uint n = 0u, last = 0u;
        for (bool first = true;; first = false) {
            uint light = 0xFFFFFFFFu;
            for (uint s = 0u; s < c.sources; ++s) {
                while (!first && at[s] < c.lists[s].y && lightCandidate(c, s, at[s]) <= last) at[s]++;
                if (at[s] < c.lists[s].y) light = min(light, lightCandidate(c, s, at[s]));
            }
            if (light == 0xFFFFFFFFu) break;
            last = light;
            GpuLight l = lights.l[light];
            if (!chunkKeepsLight(l, boxMin, boxMax, corners)) continue;
            uint mask = lightBlockerMask(lf, l, corners, boxMin, boxMax);
            if (mask == LIGHT_INVALID) {
                culledByBlockers += walk == 0u ? 1u : 0u;
                continue;
            }
            if (walk == 0u) {
                perPixel = perPixel || mask != 0u;
                features |= entryFeatures(lf, l, mask, corners);
                uint bit = 1u << (light & 31u);
                if ((visible.v[light >> 5] & bit) == 0u) atomicOr(visible.v[light >> 5], bit);
            } else {
                pool.e[base + n] = uvec2(light, mask);
            }
            n++;
        }
        if (walk == 0u) {
            kept = n;
            base = kept == 0u ? 0u : atomicAdd(UintBuffer(sf.chunkListCount).v[0], kept);
            if (base > sf.chunkListCapacity || kept > sf.chunkListCapacity - base)
                return uvec2(0u, CHUNK_LIST_NONE);
        }
    }
    return uvec2(base, kept);
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    LightingFrame lf = LightingFrameRef(f.lighting).l;
    SpectraFrame sf = SpectraFrameRef(lf.chunkSpectra).s;
    UintBuffer counts = UintBuffer(sf.chunkListCount);
    uint index = dispatch2dGroup() * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
    if (index >= counts.v[SPECTRA_LONG_LIST_DISPATCH + 3u]) return;
    uvec4 a = Uvec4Buffer(sf.longChunks).v[2u * index];
    uvec4 b = Uvec4Buffer(sf.longChunks).v[2u * index + 1u];
    uint workIndex = a.x;
    vec3 boxMin = uintBitsToFloat(a.yzw), boxMax = uintBitsToFloat(b.xyz);
    uint features = b.w; // the frame's and the material's, from classify
    vec3 corners[8];
    for (int i = 0; i < 8; ++i) corners[i] = boxCorner(boxMin, boxMax, i);
    uint kept, culledByBlockers;
    bool perPixel;
    uvec2 range = writeLongList(f, lf, sf, boxMin, boxMax, corners, kept, culledByBlockers,
                                perPixel, features);
    ChunkListBuffer(sf.chunkRanges).e[workIndex] = range;
    if (range.y == CHUNK_LIST_NONE) atomicAdd(counts.v[1], 1u);
    // Classify binned it to the mode covering every lighting feature; counted with what it needs.
    countSpectrumFeatures(sf, spectrumModeOf(sf, b.w | SPECTRUM_ALL_LIGHTING), features);
    LightingCountersRef lc = LightingCountersRef(lf.counters);
    if (kept != 0u) atomicAdd(lc.c.lightChunkPairs, kept);
    if (culledByBlockers != 0u) atomicAdd(lc.c.lightsCulledByBlockers, culledByBlockers);
    if (perPixel) atomicAdd(lc.c.perPixelBlockerChunks, 1u);
}
