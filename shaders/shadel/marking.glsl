// Marking, shared by the raster marking (mark.frag) and the compute marking over the visibility
// buffer (mark_visibility.comp): a visible sample ORs into the occupancy masks the bits of every
// chunk the reconstruction filter will read: the 2x2 bilinear taps of both MIPs of the trilinear
// blend, across chunk and block edges, at every anisotropic tap (shadelAniso).
#ifndef SHADEL_MARKING_GLSL
#define SHADEL_MARKING_GLSL
#include "shadel/shadel.glsl"

#ifdef SHADEL_MARK_CACHE
// The last chunks this invocation marked (block << 6 | bit), for invocations that mark several
// pixels: repeats skip even the load of the mask.
uint gMarked0 = SHADEL_INVALID, gMarked1 = SHADEL_INVALID, gMarked2 = SHADEL_INVALID,
     gMarked3 = SHADEL_INVALID;
#endif

void markChunk(ShadelFrame s, uvec2 sheet) {
    uint block = blockIndex(s, sheet);
    uint64_t bit = 1ul << chunkBit(sheet);
#ifdef SHADEL_MARK_CACHE
    uint key = (block << 6) | chunkBit(sheet);
    if (gMarked0 == key || gMarked1 == key || gMarked2 == key || gMarked3 == key) return;
    gMarked3 = gMarked2;
    gMarked2 = gMarked1;
    gMarked1 = gMarked0;
    gMarked0 = key;
#endif
    Uint64Buffer occupancy = Uint64Buffer(s.occupancy);
    // Most pixels find their chunk already marked: skip the atomic then.
    if ((occupancy.v[block] & bit) == 0ul) atomicOr(occupancy.v[block], bit);
}

void markFootprint(ShadelFrame s, LevelFootprint fp) {
    uvec2 a = fp.lo, b = fp.hi;
    // The four taps span at most 2x2 chunks; mark each distinct one.
    markChunk(s, a);
    if (b.x / SHADEL_CHUNK != a.x / SHADEL_CHUNK) markChunk(s, uvec2(b.x, a.y));
    if (b.y / SHADEL_CHUNK != a.y / SHADEL_CHUNK) markChunk(s, uvec2(a.x, b.y));
    if (b.x / SHADEL_CHUNK != a.x / SHADEL_CHUNK && b.y / SHADEL_CHUNK != a.y / SHADEL_CHUNK) markChunk(s, b);
}

// A level the sample wanted but whose window did not hold it: grow the level's wanted box
// (read back; next frame's window covers it). Most such samples find the box already grown.
void wantLevel(ShadelFrame s, ShadelObjectRef o, uint mip, vec2 uv) {
    ivec2 t0;
    vec2 w;
    bilinearFootprint(o, mip, uv, t0, w);
    uvec2 lo = levelTexel(o, mip, t0) / SHADEL_BLOCK, hi = levelTexel(o, mip, t0 + ivec2(1)) / SHADEL_BLOCK;
    uvec4 box = uvec4(0xFFFFu - lo, hi + 1u);
    Uvec4Buffer wants = Uvec4Buffer(s.levelWants);
    uint at = o.v.firstRect + (mip - o.v.firstMip);
    uvec4 known = wants.v[at];
    if (all(lessThanEqual(box, known))) return;
    atomicMax(wants.v[at].x, box.x);
    atomicMax(wants.v[at].y, box.y);
    atomicMax(wants.v[at].z, box.z);
    atomicMax(wants.v[at].w, box.w);
}

// What marking found for a sample's first tap: the levels after fitting to the windows and
// their footprints, exactly what reconstruction will read (the compute marking hands them to
// the resolve: shadel/resolve_address.glsl).
struct MarkedSample {
    ShadelLevels levels;
    LevelFootprint footprint0; // at levels.mip0
    LevelFootprint footprint1; // at levels.mip1 (when levels.two)
    bool windowFallback;       // a wanted level's window did not hold the tap
    bool forward; // its window fell back too far: the resolve shades it forward
    uint taps;
};

// texelDx/Dy: screen derivatives of the sample's MIP-0 shadel coordinate (shadelUv * mip0Size).
// markSampleWith: with the levels and anisotropy already taken from the derivatives (a quad's
// pixels of one triangle share them: vis_shadel.glsl).
MarkedSample markSampleWith(ShadelFrame s, ShadelObjectRef o, vec2 shadelUv, ShadelLevels wanted,
                            ShadelAniso a) {
    MarkedSample m;
    m.taps = a.taps;
    for (uint i = 0u; i < a.taps; ++i) { // the same taps reconstruction reads
        vec2 uv = shadelTapUv(o.v.mip0Size, shadelUv, a, i);
        ShadelLevels l = wanted;
        LevelFootprint fp0, fp1;
        uint unheld = fitLevelFootprints(o, uv, l, fp0, fp1);
        for (uint k = wanted.mip0; (unheld >> k) != 0u; ++k)
            if (((unheld >> k) & 1u) != 0u) wantLevel(s, o, k, uv);
        markFootprint(s, fp0);
        if (l.two) markFootprint(s, fp1);
        if (i == 0u) {
            m.levels = l;
            m.footprint0 = fp0;
            m.footprint1 = fp1;
            m.windowFallback = unheld != 0u;
            m.forward = windowFallbackTooDeep(wanted, l);
        }
    }
    return m;
}
MarkedSample markSample(ShadelFrame s, ShadelObjectRef o, vec2 shadelUv, vec2 texelDx,
                        vec2 texelDy) {
    return markSampleWith(s, o, shadelUv,
                          shadelLevels(o, texelDx, texelDy, s.shadingBias, s.trilinearBand),
                          shadelAniso(texelDx, texelDy));
}
#endif
