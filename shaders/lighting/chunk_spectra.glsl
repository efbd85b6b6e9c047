// Feature spectra of the shadel path (seed 001's spectra, "the same for chunk queues"; see
// render/lighting/feature_spectra.h). shade.comp is compiled three ways by kChunkSpectraPhase:
//   OFF:      one pass over the whole shading queue with every feature (--spectra off);
//   CLASSIFY: per queued chunk, the carry-over decision, then the chunk's light culling, the
//             features its list needs (the entryFeatures of a screen tile, against the chunk's
//             box) and an append to the bin of the first mode covering them; nothing is shaded;
//   SHADE:    one permutation per mode (kSpectrumFeatures holds only its features) over its
//             bin, by indirect dispatch: the chunk is culled again (the same list, so the same
//             features) and shaded.
// Included by shade.comp; the classify phase's function is chunk_spectra_classify.glsl.
#ifndef SHADEL_CHUNK_SPECTRA_GLSL
#define SHADEL_CHUNK_SPECTRA_GLSL
#include "lighting/spectra.glsl"

#define CHUNK_SPECTRA_OFF 0u
#define CHUNK_SPECTRA_CLASSIFY 1u
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

// --visualize spectra: the shadels of a chunk take its mode's colour.
vec3 visualizeChunkSpectrum(FrameConstants f, vec3 shaded) {
    if (kChunkSpectraPhase != CHUNK_SPECTRA_SHADE || f.visualize != VISUALIZE_SPECTRA) return shaded;
    float l = dot(shaded, vec3(0.2126, 0.7152, 0.0722));
    return mix(vec3(l / (1.0 + l)), spectrumColor(kChunkSpectrumMode), 0.6);
}
#endif
