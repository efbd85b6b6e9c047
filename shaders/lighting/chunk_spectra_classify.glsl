// The classify phase of the shadel path's feature spectra (chunk_spectra.glsl), and the
// hand-over of its culled light lists to the shading permutations. Included by shade.comp after
// its chunk light culling, whose box (gChunkBox*) and shared list it reads and writes.
#ifndef SHADEL_CHUNK_SPECTRA_CLASSIFY_GLSL
#define SHADEL_CHUNK_SPECTRA_CLASSIFY_GLSL
#include "lighting/chunk_spectra.glsl"

layout(buffer_reference, scalar) buffer ChunkListBuffer { uvec2 e[]; };

shared uint sChunkFeatures;
shared uint sChunkListBase;

// CLASSIFY: keeps the chunk's culled list (entries as cullChunkLights left them) in the pool,
// so that its permutation need not cull it again; a chunk the pool has no room for is marked
// CHUNK_LIST_NONE and culled again there. Uniform flow, after cullChunkLights.
void storeChunkLightList(SpectraFrame sf, uint workIndex) {
    uint tid = gl_LocalInvocationIndex;
    uint count = min(sLightListCount, LIGHT_CHUNK_MAX_LIGHTS);
    if (tid == 0u) {
        uint base = count == 0u ? 0u : atomicAdd(UintBuffer(sf.chunkListCount).v[0], count);
        bool fits = base <= sf.chunkListCapacity && count <= sf.chunkListCapacity - base;
        sChunkListBase = fits ? base : CHUNK_LIST_NONE;
        ChunkListBuffer(sf.chunkRanges).e[workIndex] = uvec2(base, fits ? count : CHUNK_LIST_NONE);
    }
    barrier();
    uint base = sChunkListBase;
    if (base == CHUNK_LIST_NONE) return;
    ChunkListBuffer pool = ChunkListBuffer(sf.chunkLists);
    for (uint i = tid; i < count; i += SHADEL_CHUNK * SHADEL_CHUNK) pool.e[base + i] = sLightList[i];
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

// CLASSIFY: after cullChunkLights, bins the chunk by the features of its list and of its
// object's material (featuredMaterial: it uses a MATERIAL_FEATURE_*). Uniform flow.
void classifyChunkSpectrum(FrameConstants f, uint workIndex, bool featuredMaterial) {
    LightingFrame lf = LightingFrameRef(f.lighting).l;
    uint tid = gl_LocalInvocationIndex;
    if (tid == 0u) sChunkFeatures = 0u;
    barrier();
    bool culled = gLightListMode == LIGHT_LIST_SHARED;
    bool anyShadel = gChunkHasBox;
    if (culled && anyShadel) {
        vec3 boxMin = gChunkBoxMin, boxMax = gChunkBoxMax;
        vec3 corners[8];
        for (int i = 0; i < 8; ++i) corners[i] = boxCorner(boxMin, boxMax, i);
        LightBuffer lights = LightBuffer(f.lights);
        uint count = min(sLightListCount, LIGHT_CHUNK_MAX_LIGHTS);
        uint mine = 0u;
        for (uint i = tid; i < count; i += SHADEL_CHUNK * SHADEL_CHUNK) {
            uvec2 entry = sLightList[i];
            if (entry.x != LIGHT_INVALID) mine |= entryFeatures(lf, lights.l[entry.x], entry.y, corners);
        }
        if (mine != 0u) atomicOr(sChunkFeatures, mine);
    }
    barrier();
    if (culled) storeChunkLightList(SpectraFrameRef(lf.chunkSpectra).s, workIndex);
    if (tid != 0u) return;
    // Without a culled list (no tiled culling this frame) every light may reach it.
    uint material = featuredMaterial ? SPECTRUM_MATERIAL : 0u;
    uint features = !culled      ? SPECTRUM_ALL
                    : anyShadel ? sChunkFeatures | frameFeatures(f, lf) | material
                                : 0u;
    binChunkSpectrum(lf, workIndex, features);
}

#endif
