#version 460
// Tiled light culling: one workgroup per 16x16-pixel screen tile, 8x8 invocations
// reading four of its pixels each (common/tile_frustum.glsl, TILE_CULL_THREADS). The tile's
// depth bounds come from the prepass depth; every light's sphere is tested against the tile's
// depth-bounded frustum (its clip plane and an area light's back side against the frustum's
// corners, a spot's cone against the frustum's bounding sphere); then, for lights
// with blockers, each blocker's shadow volume from the light: a blocker that covers the whole
// tile removes the light, one that covers part of it is kept as a (light, blocker) pair for the
// per-pixel test. Lists keep the lights' order (ordered compaction), so tiled shading sums in
// the same order as shading without culling. Barriers are few (five on the grid's path): where
// a workgroup's invocations run in turn (lavapipe) they are most of a tile's cost; the small
// serial steps (compaction of the grid's bit set, the copy of the kept lights) run on one.
// With feature spectra the tile also records whether any of its pixels' materials uses a
// material feature (SPECTRUM_MATERIAL), read from the visibility buffer.
#define LIGHT_CULL_ORDERED_APPEND
#include "lighting/light_cull.glsl"
#include "lighting/spectra.glsl"
#include "common/visibility.glsl"
#include "common/tile_frustum.glsl"
#extension GL_KHR_shader_subgroup_arithmetic : require

layout(local_size_x = TILE_CULL_SIDE, local_size_y = TILE_CULL_SIDE) in;
layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint depthSlot;
    uint visibilitySlot; // NO_TEXTURE without feature spectra
} pc;

#define THREADS TILE_CULL_THREADS
shared uint sDepthMin, sDepthMax;
shared uint sMaterialFeatures; // SPECTRUM_MATERIAL when a pixel's material uses any feature
shared uvec2 sList[LIGHT_TILE_MAX_LIGHTS];
shared uint sKept;
// A bit per entry of sList: the light reads a texture (lightSamplesTextures), so it is listed
// after those that do not.
shared uint sSamplesTextures[LIGHT_TILE_MAX_LIGHTS / 32u];
#define LIGHT_GRID_LIST sList
#define LIGHT_GRID_LIST_MAX LIGHT_TILE_MAX_LIGHTS
#include "lighting/light_grid.glsl"

// The tile's test of one light: its sphere against the depth-bounded tile frustum's planes and
// box, its clip plane and (area lights) back side against the frustum's corners, a spot's cone
// against the frustum's bounding sphere (centre, radius).
bool tileKeepsLight(GpuLight light, vec4 planes[6], vec3 boxMin, vec3 boxMax, vec3 corners[8],
                    vec3 centre, float radius) {
    vec4 sphere = lightSphere(light);
    bool keep = true;
    if (sphere.w >= 0.0) {
        for (int p = 0; p < 6; ++p)
            keep = keep && dot(planes[p].xyz, sphere.xyz) + planes[p].w >= -sphere.w;
        keep = keep && lightSphereMeetsBox(light, sphere, boxMin, boxMax);
    }
    return keep && !lightPlanesCull(light, corners) && !spotConeMisses(light, centre, radius);
}

// Whether the CPU's frustum cull kept the light (its list is in light order): grid candidates
// outside the camera frustum stay out, as the loop over the frustum's lights leaves them.
bool inFrustumLights(UintBuffer frustumLights, uint count, uint index) {
    uint lo = 0u, hi = count;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        uint v = frustumLights.v[mid];
        if (v == index) return true;
        if (v < index) lo = mid + 1u; else hi = mid;
    }
    return false;
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    LightingFrame lf = LightingFrameRef(f.lighting).l;
    uint tid = gl_LocalInvocationIndex;
    uint tile = gl_WorkGroupID.y * lf.tilesX + gl_WorkGroupID.x;
    if (tid == 0u) {
        sDepthMin = 0xFFFFFFFFu;
        sDepthMax = 0u;
        sAppendCount = 0u;
        sKept = 0u;
        sMaterialFeatures = 0u;
    }
    for (uint i = tid; i < LIGHT_TILE_MAX_LIGHTS / 32u; i += THREADS) sSamplesTextures[i] = 0u;
    // The light grid's bit set, cleared under the same barrier.
    lightGridMaskClearUnsynced(f, lf.lightGrid, THREADS);
    barrier();
    // Depth bounds of the tile's covered pixels (reversed Z: 0 is the far plane, the sky), and
    // whether any of their materials has a feature (with spectra): reduced over the subgroup
    // first, one shared atomic per subgroup.
    ivec2 size = ivec2(f.viewportSize);
    uint depthMin = 0xFFFFFFFFu, depthMax = 0u;
    bool featured = false;
    for (uint q = 0u; q < 4u; ++q) {
        ivec2 pixel = tileCullPixel(q);
        float d = all(lessThan(pixel, size)) ? fetchTextureUniform(pc.depthSlot, pixel, 0).r : 0.0;
        tileDepthBoundsAdd(d, depthMin, depthMax);
        if (d > 0.0 && pc.visibilitySlot != NO_TEXTURE) {
            uint instance = loadVisibility(pc.visibilitySlot, pixel).x;
            if (instance != VISIBILITY_NONE) {
                uint material = InstanceBuffer(f.instances).i[instance].material;
                featured = featured ||
                           (MaterialBuffer(f.materials).m[material].flags & MATERIAL_FEATURED) != 0u;
            }
        }
    }
    depthMin = subgroupMin(depthMin);
    depthMax = subgroupMax(depthMax);
    if (subgroupElect() && depthMax != 0u) {
        atomicMin(sDepthMin, depthMin);
        atomicMax(sDepthMax, depthMax);
    }
    if (subgroupAny(featured) && subgroupElect()) atomicOr(sMaterialFeatures, SPECTRUM_MATERIAL);
    barrier();
    if (sDepthMax == 0u) { // nothing but sky
        if (tid == 0u) {
            LightListBuffer(lf.tileRanges).e[tile] = uvec2(0u);
            binTileSpectrum(lf, tile, 0u); // sky: nothing to light
        }
        return;
    }
    // The tile's frustum between its depth bounds.
    TileFrustum t = tileFrustum(f, gl_WorkGroupID.xy, uintBitsToFloat(sDepthMax), uintBitsToFloat(sDepthMin));
    vec3 corners[8] = t.corners;
    vec4 planes[6] = t.planes;
    vec3 boxMin = t.boxMin, boxMax = t.boxMax, centre = t.centre;
    float radius = t.radius;

    // Lights against the tile, kept in light order: the frustum's lights near the tile's box
    // from the light grid (render/lighting/light_grid.h), or, where the grid cannot answer
    // (no grid, a box larger than its cells), every frustum light, THREADS at a time.
    LightBuffer lights = LightBuffer(f.lights);
    UintBuffer frustumLights = UintBuffer(lf.frustumLights);
    LightGridQuery grid;
    if (lightGridQuery(f, lf.lightGrid, boxMin, boxMax, grid)) { // (its bit set is cleared)
        UintBuffer entries = UintBuffer(grid.g.entries);
        LightGridCandidates candidates = lightGridCandidates(grid);
        for (uint k = tid; k < candidates.total; k += THREADS) {
            uint index = entries.v[lightGridCandidateEntry(candidates, k)];
            if (tileKeepsLight(lights.l[index], planes, boxMin, boxMax, corners, centre, radius) &&
                inFrustumLights(frustumLights, lf.frustumLightCount, index))
                atomicOr(sGridMask[index >> 5], 1u << (index & 31u));
        }
        barrier();
        lightGridMaskCompact(f.lightCount);
    } else {
        for (uint base = 0u; base < lf.frustumLightCount; base += THREADS) {
            uint index = base + tid < lf.frustumLightCount ? frustumLights.v[base + tid] : LIGHT_INVALID;
            bool keep = index != LIGHT_INVALID &&
                        tileKeepsLight(lights.l[index], planes, boxMin, boxMax, corners, centre, radius);
            uint slot = orderedAppend(keep);
            if (slot < LIGHT_TILE_MAX_LIGHTS) sList[slot] = uvec2(index, 0u);
        }
    }
    barrier(); // the list and its count were written by other invocations
    uint candidates = min(sAppendCount, LIGHT_TILE_MAX_LIGHTS);
    if (tid == 0u && sAppendCount > LIGHT_TILE_MAX_LIGHTS)
        atomicAdd(LightingCountersRef(lf.counters).c.tilesOverflowed, 1u);

    // Blockers: remove the lights a blocker hides from the whole tile, mark the partial ones.
    uint kept = 0u;
    for (uint i = tid; i < candidates; i += THREADS) {
        GpuLight light = lights.l[sList[i].x];
        uint mask = lightBlockerMask(lf, light, corners, boxMin, boxMax);
        sList[i].y = mask;
        if (mask == LIGHT_INVALID) sList[i].x = LIGHT_INVALID;
        kept += mask == LIGHT_INVALID ? 0u : 1u;
        if (mask != LIGHT_INVALID && lightSamplesTextures(lf, light))
            atomicOr(sSamplesTextures[i >> 5], 1u << (i & 31u));
    }
    atomicAdd(sKept, kept);
    barrier();
    // The tile's place in the shared pool (lists take what they need, not a worst case each),
    // and its kept lights copied there in order by one invocation: a tile keeps tens of lights,
    // and a walk over them costs less than a parallel ordered append's barriers.
    if (tid != 0u) return;
    LightingCountersRef counters = LightingCountersRef(lf.counters);
    uint keptLights = sKept;
    atomicAdd(counters.c.lightsCulledByBlockers, candidates - keptLights);
    uint poolBase = atomicAdd(counters.c.tileListEntries, keptLights);
    uint room = poolBase < lf.poolCapacity ? lf.poolCapacity - poolBase : 0u;
    if (room < keptLights) atomicAdd(counters.c.tilesOverflowed, 1u);
    keptLights = min(keptLights, room);
    atomicAdd(counters.c.lightTilePairs, keptLights);
    LightListBuffer outList = LightListBuffer(lf.tileLights + uint64_t(poolBase) * 8ul);
    uint features = 0u;
    bool anyPerPixel = false;
    uint written = 0u;
    // The lights that read no texture come first, each part in light order: shadeSurface runs
    // them in a loop compiled without that code (lighting.glsl, kSpectrumLightSplit), and the
    // tile's range carries where the parts meet.
    bool spectra = lf.spectra != 0ul;
    uint plain = 0u;
    for (uint part = 0u; part < 2u; ++part) {
        for (uint i = 0u; i < candidates && written < keptLights; ++i) {
            uvec2 entry = sList[i];
            if (entry.x == LIGHT_INVALID) continue;
            if (((sSamplesTextures[i >> 5] >> (i & 31u)) & 1u) != part) continue;
            if (spectra) features |= entryFeatures(lf, lights.l[entry.x], entry.y, corners);
            outList.e[written++] = entry;
            anyPerPixel = anyPerPixel || entry.y != 0u;
            atomicOr(UintBuffer(lf.visibleLights).v[entry.x >> 5], 1u << (entry.x & 31u));
        }
        if (part == 0u) plain = written;
    }
    LightListBuffer(lf.tileRanges).e[tile] = uvec2(poolBase, packTileListLength(keptLights, plain));
    atomicAdd(counters.c.lightTilePlainPairs, plain);
    if (anyPerPixel) atomicAdd(counters.c.perPixelBlockerTiles, 1u);
    binTileSpectrum(lf, tile, features | frameFeatures(f, lf) | sMaterialFeatures);
}
