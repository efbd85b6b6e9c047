// Reconstruction (seed: "Scene Render"), shared by the raster reconstruction (reconstruct.frag)
// and the compute resolve over the visibility buffer (resolve.comp): offset map + popcount find
// each tap's chunk in storage, bilinear across chunk edges and trilinear across MIPs. A tap
// whose chunk was never marked is a miss (counted; must be 0); a tap whose chunk overflowed
// storage is counted too. Either way the caller shades the pixel forward with the same
// material code, so the image never shows a hole.
#ifndef SHADEL_RESOLVE_GLSL
#define SHADEL_RESOLVE_GLSL
#include "shadel/shadel.glsl"

vec3 sampleLevel(ShadelFrame s, ShadelObjectRef o, uint mip, vec2 uv, uint layerSlot,
                 inout uint missing, inout uint overflowed, out uint64_t firstMask) {
    ivec2 t0;
    vec2 w;
    bilinearFootprint(o, mip, uv, t0, w);
    vec3 sum = vec3(0.0);
    firstMask = 0ul;
    // Most footprints (49 of 64 positions) lie inside one chunk, and a chunk's 8x8 shadels sit
    // together in storage: one lookup and one hardware-filtered fetch then replace four taps
    // (as virtual texturing samples inside a page). Chunk edges are at multiples of 8 of the
    // level's texel coordinate because every level's rect starts on a block.
    ivec2 levelSize = ivec2(levelSize(o, mip));
    if (all(greaterThanEqual(t0, ivec2(0))) && all(lessThan(t0 + 1, levelSize)) &&
        all(notEqual(t0 & 7, ivec2(7)))) {
        uvec2 sheet = sheetShadel(o, mip, t0);
        uint block = blockIndex(s, sheet);
        uint64_t mask = Uint64Buffer(s.occupancy).v[block];
        uint base = UintBuffer(s.offsetMap).v[block];
        firstMask = mask;
        uint bit = chunkBit(sheet);
        if ((mask & (1ul << bit)) == 0ul) { missing += 4u; return sum; }
        if (base == SHADEL_INVALID) { overflowed += 4u; return sum; }
        ivec2 texel = storageTexel(s, chunkSlot(mask, base, bit), sheet % SHADEL_CHUNK);
        vec2 storageSize = vec2(textureSize(gTextures[layerSlot], 0));
        vec2 at = (vec2(texel) + 0.5 + w) / storageSize;
        return textureLod(sampler2D(gTextures[layerSlot], gSamplers[SAMPLER_LINEAR_CLAMP]), at, 0.0).rgb;
    }
    // Across chunk edges, four taps. They usually share one block: look its mask and base up once.
    uint cachedBlock = SHADEL_INVALID;
    uint64_t mask = 0ul;
    uint base = SHADEL_INVALID;
    for (int i = 0; i < 4; ++i) {
        ivec2 offset = ivec2(i & 1, i >> 1);
        uvec2 sheet = sheetShadel(o, mip, t0 + offset);
        uint block = blockIndex(s, sheet);
        if (block != cachedBlock) {
            cachedBlock = block;
            mask = Uint64Buffer(s.occupancy).v[block];
            base = UintBuffer(s.offsetMap).v[block];
        }
        if (i == 0) firstMask = mask;
        uint bit = chunkBit(sheet);
        if ((mask & (1ul << bit)) == 0ul) { missing++; continue; }
        if (base == SHADEL_INVALID) { overflowed++; continue; }
        uint slot = chunkSlot(mask, base, bit);
        vec3 c = fetchTextureUniform(layerSlot, storageTexel(s, slot, sheet % SHADEL_CHUNK), 0).rgb;
        float weight = (offset.x == 1 ? w.x : 1.0 - w.x) * (offset.y == 1 ? w.y : 1.0 - w.y);
        sum += c * weight;
    }
    return sum;
}

struct Reconstruction {
    vec3 color;
    uint missing;    // taps that found no marked chunk
    uint overflowed; // taps whose chunk got no storage
    uint64_t mask0;  // occupancy of the first tap's block (marking view)
    float lod;       // of the first tap, after fitting to the level windows
    uint mip0;
    bool windowFallback; // a level the sample wanted was outside its window: read coarser
    bool sampled;   // a pixel of the statistics sample (one of every 2x2)
    bool magnified; // ... whose MIP-0 shadel is larger than the pixel
};

// texelDx/Dy: screen derivatives of the MIP-0 shadel coordinate; pixel: for the sampled
// statistics (one pixel of every 2x2). The caller counts (countReconstruction or its own sums).
// layerSlot: the storage layer to read (the radiance layer, or another for --visualize layer:X).
Reconstruction reconstructSample(ShadelFrame s, ShadelObjectRef o, vec2 shadelUv, vec2 texelDx,
                                 vec2 texelDy, ivec2 pixel, uint layerSlot) {
    ShadelLevels wanted = shadelLevels(o, texelDx, texelDy, s.shadingBias, s.trilinearBand);
    Reconstruction r;
    r.missing = 0u;
    r.overflowed = 0u;
    r.mask0 = 0ul;
    r.windowFallback = false;
    uint64_t mask1, tapMask;
    ShadelAniso a = shadelAniso(texelDx, texelDy);
    r.color = vec3(0.0);
    for (uint i = 0u; i < a.taps; ++i) { // the same taps and levels marking marked
        vec2 uv = shadelTapUv(o.v.mip0Size, shadelUv, a, i);
        ShadelLevels l = wanted;
        r.windowFallback = r.windowFallback || fitLevelsToWindows(o, uv, l) != 0u;
        vec3 c = sampleLevel(s, o, l.mip0, uv, layerSlot, r.missing, r.overflowed, tapMask);
        if (i == 0u) {
            r.mask0 = tapMask;
            r.mip0 = l.mip0;
            r.lod = float(l.mip0) + l.blend;
        }
        if (l.two) c = mix(c, sampleLevel(s, o, l.mip1, uv, layerSlot, r.missing, r.overflowed, mask1), l.blend);
        r.color += c;
    }
    r.color /= float(a.taps);

    // Magnification: the MIP-0 shadel is larger than the pixel along the longer screen axis.
    // Counted on one pixel of every 2x2 (a fraction needs no more, and atomics cost).
    r.sampled = all(equal(pixel & 1, ivec2(0)));
    r.magnified = r.sampled && max(dot(texelDx, texelDx), dot(texelDy, texelDy)) < 1.0;
    return r;
}

// The storage layer the reconstruction shows: radiance, or the material layer for
// --visualize layer:material.
uint reconstructionLayer(FrameConstants f, ShadelFrame s) {
    return f.visualize == VISUALIZE_LAYER_MATERIAL ? s.layerReadSlot[SHADEL_LAYER_MATERIAL]
                                                   : s.storageReadSlot;
}

// The frame's counters, one pixel at a time (raster reconstruction).
void countReconstruction(ShadelFrame s, Reconstruction r) {
    ShadelCountersRef counters = ShadelCountersRef(s.counters);
    if (r.magnified) atomicAdd(counters.c.magnifiedPixels, 1u);
    if (r.sampled && r.windowFallback) atomicAdd(counters.c.windowFallbackPixels, 1u);
    if (r.sampled) atomicAdd(counters.c.reconstructedPixels, 1u);
    if (r.missing != 0u) atomicAdd(counters.c.reconstructionMisses, 1u);
    if (r.overflowed != 0u) atomicAdd(counters.c.overflowSamples, 1u);
}

vec3 heat(float t) {
    t = clamp(t, 0.0, 1.0);
    return clamp(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0), 1.5 - abs(4.0 * t - 1.0)), 0.0, 1.0);
}

// The debug views (--visualize marking|mips|chunks) over the reconstructed colour.
vec3 visualizeReconstruction(FrameConstants f, ShadelObjectRef o, Reconstruction r, vec3 color,
                             vec2 shadelUv, vec2 texelDx, vec2 texelDy) {
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
