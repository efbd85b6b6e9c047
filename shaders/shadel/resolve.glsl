// Reconstruction, shared by the raster reconstruction (reconstruct.frag) and the compute resolve
// over the visibility buffer (resolve.comp): offset map + popcount find each tap's chunk in
// storage, bilinear across chunk edges and trilinear across MIPs. A tap whose chunk was never
// marked is a miss (counted; must be 0); a tap whose chunk overflowed storage is counted too.
// Either way the caller shades the pixel forward with the same material code, so the image never
// shows a hole.
#ifndef SHADEL_RESOLVE_GLSL
#define SHADEL_RESOLVE_GLSL
#include "shadel/shadel.glsl"

// A chunk's storage slot from one of its sheet shadels: the block's occupancy mask and base,
// then the marked chunks before it; -1 (counted as missing or overflowed) when it has none.
int chunkSlotAt(ShadelFrame s, uvec2 sheet, inout uint missing, inout uint overflowed,
                out uint64_t mask) {
    uint block = blockIndex(s, sheet);
    mask = Uint64Buffer(s.occupancy).v[block];
    uint base = UintBuffer(s.offsetMap).v[block];
    uint bit = chunkBit(sheet);
    if ((mask & (1ul << bit)) == 0ul) { missing++; return -1; }
    if (base == SHADEL_INVALID) { overflowed++; return -1; }
    return int(chunkSlot(mask, base, bit));
}

// The stored value of a sheet shadel whose chunk has storage slot `slot` (black for -1), from
// storage layer `layer` (SHADEL_LAYER_*; the material layer shows its RGB, the base colour).
vec3 storageTap(ShadelFrame s, uint layer, int slot, uvec2 sheet) {
    if (slot < 0) return vec3(0.0);
    return loadLayer(s, layer, storageIndex(uint(slot), sheet % SHADEL_CHUNK)).rgb;
}

// The bilinear filter over a level footprint (LevelFootprint).
vec3 sampleFootprint(ShadelFrame s, LevelFootprint fp, uint layer, inout uint missing,
                     inout uint overflowed, out uint64_t firstMask, out int firstSlot) {
    // The footprint's two columns and two rows in the sheet (clamped to the level). Each of its
    // four taps reads the chunk holding it; one chunk lookup serves all four unless the
    // footprint crosses a chunk edge (15 of 64 positions), which costs only the extra lookups:
    // every lane runs the same four fetches, so a SIMD group does not run two paths. (A fast
    // path of one filtered fetch inside a chunk plus a four-tap path at chunk edges made almost
    // every group run both: 1 - (49/64)^8 of 8-lane groups have an edge lane. Measured on
    // lavapipe at 1280x720, builtin:default, orbit: resolveCompute 134-142 ms -> 107 ms.)
    uvec2 lo = fp.lo, hi = fp.hi;
    vec2 w = fp.weight;
    bvec2 cross = notEqual(lo / SHADEL_CHUNK, hi / SHADEL_CHUNK);
    uint64_t mask; // of the other lookups (only the first is reported)
    int s00 = chunkSlotAt(s, lo, missing, overflowed, firstMask);
    firstSlot = s00;
    int s10 = cross.x ? chunkSlotAt(s, uvec2(hi.x, lo.y), missing, overflowed, mask) : s00;
    int s01 = cross.y ? chunkSlotAt(s, uvec2(lo.x, hi.y), missing, overflowed, mask) : s00;
    int s11 = cross.x && cross.y ? chunkSlotAt(s, hi, missing, overflowed, mask)
              : cross.x          ? s10
                                 : s01;
    vec3 c00 = storageTap(s, layer, s00, lo);
    vec3 c10 = storageTap(s, layer, s10, uvec2(hi.x, lo.y));
    vec3 c01 = storageTap(s, layer, s01, uvec2(lo.x, hi.y));
    vec3 c11 = storageTap(s, layer, s11, hi);
    return mix(mix(c00, c10, w.x), mix(c01, c11, w.x), w.y);
}

struct Reconstruction {
    vec3 color;
    uint missing;    // chunk lookups that found no marked chunk
    uint overflowed; // chunk lookups whose chunk got no storage
    uint64_t mask0;  // occupancy of the first tap's block (marking view)
    int slot0;       // storage slot of the first tap's chunk, -1 if none (reuse view)
    float lod;       // of the first tap, after fitting to the level windows
    uint mip0;
    bool windowFallback; // a level the sample wanted was outside its window: read coarser
    bool forward; // ... so far outside that the caller shades it forward instead
    bool sampled;   // a pixel of the statistics sample (one of every 2x2)
    bool magnified; // ... whose MIP-0 shadel is larger than the pixel
};

// texelDx/Dy: screen derivatives of the MIP-0 shadel coordinate; pixel: for the sampled
// statistics (one pixel of every 2x2). The caller counts (countReconstruction or its own sums).
// layer: the storage layer to read (SHADEL_LAYER_RADIANCE, or another for --visualize layer:X).
Reconstruction reconstructSample(ShadelFrame s, ShadelObjectRef o, vec2 shadelUv, vec2 texelDx,
                                 vec2 texelDy, ivec2 pixel, uint layer) {
    ShadelLevels wanted = shadelLevels(o, texelDx, texelDy, s.shadingBias, s.trilinearBand);
    Reconstruction r;
    r.missing = 0u;
    r.overflowed = 0u;
    r.mask0 = 0ul;
    r.windowFallback = false;
    uint64_t mask1, tapMask;
    int slot1, tapSlot;
    r.slot0 = -1;
    ShadelAniso a = shadelAniso(texelDx, texelDy);
    r.color = vec3(0.0);
    for (uint i = 0u; i < a.taps; ++i) { // the same taps and levels marking marked
        vec2 uv = shadelTapUv(o.v.mip0Size, shadelUv, a, i);
        ShadelLevels l = wanted;
        LevelFootprint fp0, fp1;
        r.windowFallback = fitLevelFootprints(o, uv, l, fp0, fp1) != 0u || r.windowFallback;
        vec3 c = sampleFootprint(s, fp0, layer, r.missing, r.overflowed, tapMask, tapSlot);
        if (i == 0u) {
            r.mask0 = tapMask;
            r.slot0 = tapSlot;
            r.mip0 = l.mip0;
            r.lod = float(l.mip0) + l.blend;
            r.forward = windowFallbackTooDeep(wanted, l); // as marking decided
        }
        if (l.two)
            c = mix(c, sampleFootprint(s, fp1, layer, r.missing, r.overflowed, mask1, slot1), l.blend);
        r.color += c;
    }
    r.color /= float(a.taps);

    // Magnification: the MIP-0 shadel is larger than the pixel along the longer screen axis.
    // Counted on one pixel of every 2x2 (a fraction needs no more, and atomics cost).
    r.sampled = all(equal(pixel & 1, ivec2(0)));
    r.magnified = r.sampled && max(dot(texelDx, texelDx), dot(texelDy, texelDy)) < 1.0;
    return r;
}

// The storage layer the reconstruction shows (SHADEL_LAYER_*): radiance, or the material layer
// for --visualize layer:material.
uint reconstructionLayer(FrameConstants f, ShadelFrame s) {
    return f.visualize == VISUALIZE_LAYER_MATERIAL ? SHADEL_LAYER_MATERIAL : SHADEL_LAYER_RADIANCE;
}

// The frame's counters, one pixel at a time (raster reconstruction).
void countReconstruction(ShadelFrame s, Reconstruction r) {
    ShadelCountersRef counters = ShadelCountersRef(s.counters);
    if (r.magnified) atomicAdd(counters.c.magnifiedPixels, 1u);
    if (r.sampled && r.windowFallback) atomicAdd(counters.c.windowFallbackPixels, 1u);
    if (r.sampled && r.forward) atomicAdd(counters.c.windowForwardPixels, 1u);
    if (r.sampled) atomicAdd(counters.c.reconstructedPixels, 1u);
    if (r.missing != 0u) atomicAdd(counters.c.reconstructionMisses, 1u);
    if (r.overflowed != 0u) atomicAdd(counters.c.overflowSamples, 1u);
}

vec3 heat(float t) {
    t = clamp(t, 0.0, 1.0);
    return clamp(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0), 1.5 - abs(4.0 * t - 1.0)), 0.0, 1.0);
}

// --visualize reuse: the colour of why the chunk in `slot` was shaded this frame
// (SHADEL_SHADED_*); carried-over chunks keep their image in grey.
vec3 reuseReasonView(ShadelFrame s, int slot, vec3 color) {
    if (slot < 0 || s.chunkReasons == 0ul) return color;
    uint reason = UintBuffer(s.chunkReasons).v[uint(slot)];
    vec3 grey = vec3(dot(min(color, vec3(1.0)), vec3(0.2126, 0.7152, 0.0722)));
    if (reason == SHADEL_CHUNK_CARRIED) return grey;
    const vec3 tints[SHADEL_SHADED_REASONS] = vec3[](
        vec3(1.0, 0.15, 0.1),  // not reusable: red
        vec3(0.1, 1.0, 0.2),   // new: green
        vec3(0.15, 0.35, 1.0), // refresh: blue
        vec3(1.0, 0.55, 0.05), // near a change: orange
        vec3(0.1, 0.9, 0.9),   // RT history: cyan
        vec3(1.0, 0.9, 0.1));  // view turned: yellow
    return mix(grey, tints[min(reason, uint(SHADEL_SHADED_REASONS - 1))], 0.6);
}

// The debug views (--visualize marking|mips|chunks|reuse) over the reconstructed colour.
vec3 visualizeReconstruction(FrameConstants f, ShadelObjectRef o, Reconstruction r, vec3 color,
                             vec2 shadelUv, vec2 texelDx, vec2 texelDy) {
    if (f.visualize == VISUALIZE_REUSE)
        color = reuseReasonView(ShadelFrameRef(f.shadel).s, r.slot0, color);
    if (f.visualize == VISUALIZE_MARKING) {
        // Seed colours: green = block with any chunk marked, blue = block fully marked.
        vec3 tint = r.mask0 == ~0ul ? vec3(0.1, 0.2, 1.0) : vec3(0.1, 1.0, 0.2);
        color = mix(color, tint, 0.5);
    } else if (f.visualize == VISUALIZE_MIPS) {
        color = heat(r.lod / 7.0);
    } else if (f.visualize == VISUALIZE_CHUNKS) {
        vec2 scale = vec2(levelSize(o, r.mip0)) / (vec2(o.v.mip0Size) * float(SHADEL_CHUNK));
        vec2 level = shadelUv * vec2(levelSize(o, r.mip0)) / float(SHADEL_CHUNK);
        vec2 edge = abs(fract(level) - 0.5);
        vec2 width = (abs(texelDx) + abs(texelDy)) * scale; // fwidth(level)
        float line = float(any(greaterThan(edge, 0.5 - width)));
        color = mix(color, vec3(1.0, 0.9, 0.1), line);
    }
#ifdef SHADEL_DEBUG_SHADERS
    const bool showMisses = true; // debug builds: a miss is never hidden by the fallback
#else
    bool showMisses = f.visualize != VISUALIZE_NONE;
#endif
    if (showMisses && r.missing != 0u) color = vec3(1.0, 0.0, 1.0);
    return color;
}
#endif
