// Feature spectra of the shadel path (the tiles' spectra applied to the chunk
// queue; see render/lighting/feature_spectra.h). Two passes:
//   classify (chunk_classify.comp, one invocation per queued chunk): the carry-over decision,
//             the chunk's light culling against its world box, the features its list needs (the
//             entryFeatures of a screen tile) and an append to the bin of the first mode
//             covering them; the list is kept for the shading;
// and shade.comp, compiled two ways by kChunkSpectraPhase:
//   OFF:      one pass over the whole shading queue with every feature (--spectra off);
//   SHADE:    one permutation per mode (kSpectrumFeatures holds only its features) over its
//             bin, by indirect dispatch: the chunk's list as classify culled it, and shading.
// Included by shade.comp.
#ifndef SHADEL_CHUNK_SPECTRA_GLSL
#define SHADEL_CHUNK_SPECTRA_GLSL
#include "lighting/spectra.glsl"

#define CHUNK_SPECTRA_OFF 0u
#define CHUNK_SPECTRA_SHADE 2u
layout(constant_id = CHUNK_SPECTRA_PHASE_CONSTANT_ID) const uint kChunkSpectraPhase = CHUNK_SPECTRA_OFF;
layout(constant_id = SPECTRUM_MODE_CONSTANT_ID) const uint kChunkSpectrumMode = 0u;

// The shading queue's index of this workgroup's chunk: the workgroup itself, or in a spectrum's
// permutation the group-th entry of its bin (0xFFFFFFFF past its end).
uint chunkSpectraWorkIndex(FrameConstants f, uint group) {
    if (kChunkSpectraPhase != CHUNK_SPECTRA_SHADE) return group;
    SpectraFrame sf = SpectraFrameRef(LightingFrameRef(f.lighting).l.chunkSpectra).s;
    if (group >= UintBuffer(sf.dispatch).v[kChunkSpectrumMode * 4u + 3u]) return 0xFFFFFFFFu;
    return UintBuffer(sf.tileBins).v[kChunkSpectrumMode * sf.binCapacity + group];
}

// SHADE: the chunk's list as the classify pass culled it, read from its pool where it lies (no
// copy to shared memory: no barrier, so the permutations run without coroutines on lavapipe).
// A chunk whose list did not fit the pool takes every light, each blocker tested per shadel (the
// same sum, slower; classify binned it to every feature and counted it). Any control flow.
void loadChunkLightList(FrameConstants f, uint workIndex) {
    SpectraFrame sf = SpectraFrameRef(LightingFrameRef(f.lighting).l.chunkSpectra).s;
    uvec2 range = ChunkListBuffer(sf.chunkRanges).e[workIndex];
    if (range.y == CHUNK_LIST_NONE) {
        gLightListMode = LIGHT_LIST_ALL;
        return;
    }
    gLightListMode = LIGHT_LIST_BUFFER;
    gLightListAddress = sf.chunkLists + uint64_t(range.x) * 8ul;
    gLightListCount = range.y;
    gLightListPlainCount = 0u;
}

// --visualize spectra: the shadels of a chunk take its mode's colour.
vec3 visualizeChunkSpectrum(FrameConstants f, vec3 shaded) {
    if (kChunkSpectraPhase != CHUNK_SPECTRA_SHADE || f.visualize != VISUALIZE_SPECTRA) return shaded;
    float l = dot(shaded, vec3(0.2126, 0.7152, 0.0722));
    return mix(vec3(l / (1.0 + l)), spectrumColor(kChunkSpectrumMode), 0.6);
}
#endif
