// The classify phase of the shadel path's feature spectra (chunk_spectra.glsl). Included by
// shade.comp after its chunk light culling, whose box (gChunkBox*) and shared list it reads.
#ifndef SHADEL_CHUNK_SPECTRA_CLASSIFY_GLSL
#define SHADEL_CHUNK_SPECTRA_CLASSIFY_GLSL
#include "lighting/chunk_spectra.glsl"

shared uint sChunkFeatures;

// CLASSIFY: after cullChunkLights, bins the chunk by the features of its list (uniform flow).
void classifyChunkSpectrum(FrameConstants f, uint workIndex) {
    LightingFrame lf = LightingFrameRef(f.lighting).l;
    uint tid = gl_LocalInvocationIndex;
    if (tid == 0u) sChunkFeatures = 0u;
    barrier();
    bool culled = gLightListMode == LIGHT_LIST_SHARED;
    bool anyShadel = gChunkHasBox;
    if (culled && anyShadel) {
        vec3 boxMin = gChunkBoxMin, boxMax = gChunkBoxMax;
        vec3 corners[8];
        for (int i = 0; i < 8; ++i)
            corners[i] = vec3((i & 1) != 0 ? boxMax.x : boxMin.x, (i & 2) != 0 ? boxMax.y : boxMin.y,
                              (i & 4) != 0 ? boxMax.z : boxMin.z);
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
    if (tid != 0u) return;
    // Without a culled list (no tiled culling this frame) every light may reach it.
    uint features = !culled ? SPECTRUM_ALL : anyShadel ? sChunkFeatures | frameFeatures(f, lf) : 0u;
    binChunkSpectrum(lf, workIndex, features);
}

#endif
