// Reconstruction addresses (--marking visibility): the compute marking already knows, per
// pixel, which sheet shadels and weights the resolve will read (its first tap's levels after
// fitting to the windows, and their bilinear footprints). It writes them into a buffer of 16
// bytes per pixel, so the resolve skips the visibility buffer, the triangle setup, the MIP
// choice and the window fitting and does only the chunk lookups (allocation happens between the
// passes), the storage fetches and the filter.
//
// One 32-bit word per axis and level: x = mip0's column, y = mip0's row, z = mip1's column,
// w = mip1's row. Each holds the footprint's first sheet shadel on that axis (18 bits: sheets
// up to 262144 shadels a side), the bilinear weight of the second (9 bits), whether the second
// is the next shadel (else the first: clamped at the level's edge), and 4 bits of the rest:
// x: kind (2 bits), two levels, window fallback; y: magnified; z, w: the MIP blend (8 bits).
#ifndef SHADEL_RESOLVE_ADDRESS_GLSL
#define SHADEL_RESOLVE_ADDRESS_GLSL
#include "shadel/marking.glsl"

#define RESOLVE_ADDRESS_NONE 0u    // no surface: the sky
#define RESOLVE_ADDRESS_READY 1u   // the footprints below
#define RESOLVE_ADDRESS_REBUILD 2u // the resolve rebuilds the sample (more taps, or forward)
#define RESOLVE_ADDRESS_FORWARD 3u // a forward (hybrid) instance, drawn before the resolve

// Laid out by 2x2 quads, the unit both passes walk: a quad's four pixels are 64 bytes together.
layout(buffer_reference, scalar) buffer ResolveAddressBuffer { uvec4 v[]; };

uint resolveAddressIndex(ivec2 pixel, uint width) {
    uvec2 p = uvec2(pixel);
    return (((p.y >> 1) * ((width + 1u) >> 1) + (p.x >> 1)) << 2) + ((p.y & 1u) << 1) + (p.x & 1u);
}

const uint kAddressCoordBits = 18u;
const uint kAddressWeightBits = 9u;
const float kAddressWeightScale = float((1u << kAddressWeightBits) - 1u);
const uint kAddressStepBit = kAddressCoordBits + kAddressWeightBits; // 27
const uint kAddressExtraBit = 28u;                                   // 4 bits

struct ResolveAddress {
    uint kind;
    bool two;
    bool windowFallback;
    bool magnified;
    float blend; // weight of footprint1
    LevelFootprint footprint0;
    LevelFootprint footprint1;
};

uint packAddressAxis(uint lo, uint hi, float weight, uint extra) {
    // Every field is in range by construction: lo < 2^18 (the sheet), weight in [0, 1) (a
    // fraction), hi - lo in {0, 1}, extra < 16: plain shifts, no masks.
    uint w = uint(weight * kAddressWeightScale + 0.5);
    return lo | (w << kAddressCoordBits) | ((hi - lo) << kAddressStepBit) |
           (extra << kAddressExtraBit);
}

void unpackAddressAxis(uint word, out uint lo, out uint hi, out float weight) {
    lo = word & ((1u << kAddressCoordBits) - 1u);
    hi = lo + ((word >> kAddressStepBit) & 1u);
    weight = float((word >> kAddressCoordBits) & ((1u << kAddressWeightBits) - 1u)) *
             (1.0 / kAddressWeightScale);
}

uvec4 resolveAddressNone() { return uvec4(0u); } // kind RESOLVE_ADDRESS_NONE
uvec4 resolveAddressForward() {
    return uvec4(RESOLVE_ADDRESS_FORWARD << kAddressExtraBit, 0u, 0u, 0u);
}

// magnified: the MIP-0 shadel is larger than the pixel (the resolve's statistics).
uvec4 packResolveAddress(MarkedSample m, bool magnified) {
    if (m.taps != 1u || m.forward) // rare: the resolve rebuilds it
        return uvec4(RESOLVE_ADDRESS_REBUILD << kAddressExtraBit, 0u, 0u, 0u);
    uint blend = m.levels.two ? uint(m.levels.blend * 255.0 + 0.5) : 0u;
    uint extraX = RESOLVE_ADDRESS_READY | (m.levels.two ? 4u : 0u) | (m.windowFallback ? 8u : 0u);
    LevelFootprint a = m.footprint0, b = m.footprint1;
    return uvec4(packAddressAxis(a.lo.x, a.hi.x, a.weight.x, extraX),
                 packAddressAxis(a.lo.y, a.hi.y, a.weight.y, magnified ? 1u : 0u),
                 packAddressAxis(b.lo.x, b.hi.x, b.weight.x, blend & 15u),
                 packAddressAxis(b.lo.y, b.hi.y, b.weight.y, blend >> 4));
}

ResolveAddress unpackResolveAddress(uvec4 word) {
    ResolveAddress a;
    uint extraX = word.x >> kAddressExtraBit;
    a.kind = extraX & 3u;
    a.two = (extraX & 4u) != 0u;
    a.windowFallback = (extraX & 8u) != 0u;
    a.magnified = (word.y >> kAddressExtraBit) != 0u;
    a.blend = float((word.z >> kAddressExtraBit) | ((word.w >> kAddressExtraBit) << 4)) *
              (1.0 / 255.0);
    unpackAddressAxis(word.x, a.footprint0.lo.x, a.footprint0.hi.x, a.footprint0.weight.x);
    unpackAddressAxis(word.y, a.footprint0.lo.y, a.footprint0.hi.y, a.footprint0.weight.y);
    unpackAddressAxis(word.z, a.footprint1.lo.x, a.footprint1.hi.x, a.footprint1.weight.x);
    unpackAddressAxis(word.w, a.footprint1.lo.y, a.footprint1.hi.y, a.footprint1.weight.y);
    return a;
}
#endif
