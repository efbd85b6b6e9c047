// Feature spectra: the tile pass records which lighting features a tile needs and
// bins the tile into the cheapest shading permutation ("mode") whose features cover them; the
// tile shading pass (tile_shade.comp) then runs each mode's permutation over its bin through
// an indirect dispatch. See render/lighting/feature_spectra.h.
#ifndef SHADEL_SPECTRA_GLSL
#define SHADEL_SPECTRA_GLSL
#include "common/lighting.glsl"

layout(buffer_reference, scalar) readonly buffer SpectraFrameRef { SpectraFrame s; };
// SpectraFrame::chunkLists entries and ::chunkRanges (the shadel path's classified lists).
layout(buffer_reference, scalar) buffer ChunkListBuffer { uvec2 e[]; };

// The features one (light, blocker mask) entry of a tile's list asks for. `corners`: the
// tile's volume (a clip plane that leaves all of it lit needs no per-pixel test).
uint entryFeatures(LightingFrame lf, GpuLight light, uint blockerMask, vec3 corners[8]) {
    uint features = 0u;
    if (light.type == LIGHT_POINT) features |= SPECTRUM_OMNI;
    if (light.type == LIGHT_SPOT) features |= SPECTRUM_SPOT;
    if (light.type == LIGHT_SPOT_SQUARE) features |= SPECTRUM_SQUARE_SPOT;
    if (light.type == LIGHT_TUBE) features |= SPECTRUM_TUBE;
    if (light.type == LIGHT_AREA) features |= SPECTRUM_AREA;
    if ((light.flags & LIGHT_FLAG_PROJECTED) != 0u) features |= SPECTRUM_PROJECTED;
    if ((light.flags & LIGHT_FLAG_DARK) != 0u) features |= SPECTRUM_DARK;
    if ((light.flags & LIGHT_FLAG_CLIP_PLANE) != 0u) {
        bool allLit = true;
        for (int i = 0; i < 8; ++i)
            allLit = allLit && dot(light.clipPlane.xyz, corners[i]) + light.clipPlane.w >= 0.0;
        if (!allLit) features |= SPECTRUM_CLIP_PLANES;
    }
    if (light.shadowIndex != LIGHT_NO_SHADOW && lf.spotShadowAtlas != NO_TEXTURE) {
        features |= SPECTRUM_SPOT_SHADOWS;
        if ((light.flags & LIGHT_FLAG_SOFT_SHADOW) != 0u) features |= SPECTRUM_SOFT_SHADOWS;
    }
    if (blockerMask != 0u && lf.blockersOn != 0u) {
        features |= SPECTRUM_BLOCKERS;
        LightBlockerBuffer blockers = LightBlockerBuffer(lf.blockers);
        UintBuffer list = UintBuffer(lf.lightBlockers);
        uint n = min(light.blockerCount, LIGHT_MAX_BLOCKERS_PER_LIGHT);
        for (uint k = 0u; k < n; ++k)
            if ((blockerMask & (1u << k)) != 0u &&
                blockers.b[list.v[light.blockerFirst + k]].portalCount != 0u)
                features |= SPECTRUM_PORTALS;
    }
    return features;
}

// Whether the light brings any SPECTRUM_SAMPLING_LIGHTS feature (entryFeatures' texture
// reads): it goes after the lights that do not in a spectra list (shadeSurface's split).
bool lightSamplesTextures(LightingFrame lf, GpuLight light) {
    return light.type == LIGHT_AREA || (light.flags & LIGHT_FLAG_PROJECTED) != 0u ||
           (light.shadowIndex != LIGHT_NO_SHADOW && lf.spotShadowAtlas != NO_TEXTURE);
}

// Features every covered pixel of the frame needs (not per light): the sun's shadow map.
uint frameFeatures(FrameConstants f, LightingFrame lf) {
    bool sunShadow = f.sunShadowSlot != NO_TEXTURE && dot(f.sunColor, f.sunColor) > 0.0;
    if (!sunShadow) return 0u;
    return lf.sunSoftShadows != 0u ? SPECTRUM_SHADOWS | SPECTRUM_SOFT_SHADOWS : SPECTRUM_SHADOWS;
}

// The first mode (they are ordered cheapest first; the last has every feature) covering
// `features`.
uint spectrumModeOf(SpectraFrame sf, uint features) {
    for (uint m = 0u; m < sf.modeCount; ++m)
        if ((features & ~sf.modeFeatures[m]) == 0u) return m;
    return sf.modeCount - 1u;
}

// Counts the features a binned tile (or chunk) compiles in needlessly, the features it needs,
// and a histogram of the exact feature sets (what the modes are chosen from).
void countSpectrumFeatures(SpectraFrame sf, uint mode, uint features) {
    uint superfluous = sf.modeFeatures[mode] & ~features;
    for (uint bit = 0u; bit < SPECTRUM_FEATURE_COUNT; ++bit) {
        if ((superfluous & (1u << bit)) != 0u)
            atomicAdd(UintBuffer(sf.superfluous).v[mode * SPECTRUM_FEATURE_COUNT + bit], 1u);
        if ((features & (1u << bit)) != 0u) atomicAdd(UintBuffer(sf.featureTiles).v[bit], 1u);
    }
    atomicAdd(UintBuffer(sf.featureTiles).v[SPECTRUM_FEATURE_COUNT + features], 1u);
}

// Appends the tile to the bin of the first mode covering `features`.
void binTileSpectrum(LightingFrame lf, uint tile, uint features) {
    if (lf.spectra == 0ul) return;
    SpectraFrame sf = SpectraFrameRef(lf.spectra).s;
    uint mode = spectrumModeOf(sf, features);
    // x of the mode's VkDispatchIndirectCommand.
    uint slot = atomicAdd(UintBuffer(sf.dispatch).v[mode * 3u], 1u);
    UintBuffer(sf.tileBins).v[mode * sf.binCapacity + slot] = tile;
    countSpectrumFeatures(sf, mode, features);
}

// The shadel path: appends a shading chunk (its work-queue index) to its mode's bin. The
// dispatch entry of a mode is a uvec4 whose w counts the chunks; chunk_spectra_setup.comp turns
// the counts into 2-D dispatch sizes (as the shading queue's, dispatch_setup.comp).
// appendChunkToBin appends to the bin of the first mode covering `cover` and returns the mode;
// binChunkSpectrum also counts the features the chunk needs.
uint appendChunkToBin(SpectraFrame sf, uint workIndex, uint cover) {
    uint mode = spectrumModeOf(sf, cover);
    uint slot = atomicAdd(UintBuffer(sf.dispatch).v[mode * 4u + 3u], 1u);
    UintBuffer(sf.tileBins).v[mode * sf.binCapacity + slot] = workIndex;
    return mode;
}

void binChunkSpectrum(LightingFrame lf, uint workIndex, uint features) {
    if (lf.chunkSpectra == 0ul) return;
    SpectraFrame sf = SpectraFrameRef(lf.chunkSpectra).s;
    countSpectrumFeatures(sf, appendChunkToBin(sf, workIndex, features), features);
}

// A mode's colour in --visualize spectra.
vec3 spectrumColor(uint mode) {
    const vec3 palette[8] = vec3[8](vec3(0.15, 0.35, 1.0), vec3(0.1, 0.85, 0.3), vec3(1.0, 0.85, 0.1),
                                    vec3(1.0, 0.45, 0.05), vec3(0.85, 0.1, 0.9), vec3(0.1, 0.9, 0.9),
                                    vec3(0.6, 0.3, 0.1), vec3(1.0, 0.1, 0.1));
    return palette[mode % 8u] * (mode >= 8u ? 0.5 : 1.0);
}
#endif
