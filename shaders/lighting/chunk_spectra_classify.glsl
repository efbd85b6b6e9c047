// The classify phase of the shadel path's feature spectra (chunk_spectra.glsl), and the
// hand-over of its culled light lists to the shading permutations. Included by shade.comp after
// its chunk light culling, whose box (gChunkBox*), shared list and gChunkListFeatures it reads.
#ifndef SHADEL_CHUNK_SPECTRA_CLASSIFY_GLSL
#define SHADEL_CHUNK_SPECTRA_CLASSIFY_GLSL
#include "lighting/chunk_spectra.glsl"

layout(buffer_reference, scalar) buffer ChunkListBuffer { uvec2 e[]; };

// CLASSIFY, invocation 0: keeps the chunk's culled list (cullChunkLights left only the lights
// it keeps, in order) in the pool, so that its permutation need not cull it again; a chunk the pool has no
// room for is marked CHUNK_LIST_NONE and culled again there. One invocation copies the list
// (a chunk keeps a few lights): no barrier, as the screen tiles' copy (tile_cull.comp).
void storeChunkLightList(SpectraFrame sf, uint workIndex) {
    uint count = min(sLightListCount, LIGHT_CHUNK_MAX_LIGHTS);
    uint base = count == 0u ? 0u : atomicAdd(UintBuffer(sf.chunkListCount).v[0], count);
    bool fits = base <= sf.chunkListCapacity && count <= sf.chunkListCapacity - base;
    ChunkListBuffer(sf.chunkRanges).e[workIndex] = uvec2(base, fits ? count : CHUNK_LIST_NONE);
    if (!fits) return;
    ChunkListBuffer pool = ChunkListBuffer(sf.chunkLists);
    for (uint i = 0u; i < count; ++i) pool.e[base + i] = sLightList[i];
}

// SHADE: the chunk's list as its classify phase culled it, into the shared list. False (and
// nothing read) when the classify phase could not keep it: the caller culls the chunk.
// Uniform flow.
bool loadChunkLightList(FrameConstants f, uint workIndex) {
    SpectraFrame sf = SpectraFrameRef(LightingFrameRef(f.lighting).l.chunkSpectra).s;
    uvec2 range = ChunkListBuffer(sf.chunkRanges).e[workIndex];
    uint tid = gl_LocalInvocationIndex;
    if (range.y == CHUNK_LIST_NONE) {
        if (tid == 0u) atomicAdd(UintBuffer(sf.chunkListCount).v[1], 1u);
        return false;
    }
    ChunkListBuffer pool = ChunkListBuffer(sf.chunkLists);
    for (uint i = tid; i < range.y; i += SHADEL_CHUNK * SHADEL_CHUNK) sLightList[i] = pool.e[range.x + i];
    if (tid == 0u) sLightListCount = range.y;
    gLightListMode = LIGHT_LIST_SHARED;
    barrier();
    return true;
}

// CLASSIFY: after cullChunkLights, bins the chunk by the features of its list (gathered by
// invocation 0 as it walked the kept lights) and of its object's material (featuredMaterial: it
// uses a MATERIAL_FEATURE_*). Invocation 0 alone: no barrier after the culling's.
void classifyChunkSpectrum(FrameConstants f, uint workIndex, bool featuredMaterial) {
    if (gl_LocalInvocationIndex != 0u) return;
    LightingFrame lf = LightingFrameRef(f.lighting).l;
    bool culled = gLightListMode == LIGHT_LIST_SHARED;
    if (culled) storeChunkLightList(SpectraFrameRef(lf.chunkSpectra).s, workIndex);
    // Without a culled list (no tiled culling this frame) every light may reach it.
    uint material = featuredMaterial ? SPECTRUM_MATERIAL : 0u;
    uint features = !culled        ? SPECTRUM_ALL
                    : gChunkHasBox ? gChunkListFeatures | frameFeatures(f, lf) | material
                                   : 0u;
    binChunkSpectrum(lf, workIndex, features);
}

#endif
