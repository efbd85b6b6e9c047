#version 460
// Marking (seed: "Shadel Marking pass"): a raster of the decoupled objects against the prepass
// depth, with no colour output. Each visible pixel ORs into the occupancy masks the bits of
// every chunk the reconstruction filter will read: the 2x2 bilinear taps of both MIPs of the
// trilinear blend, across chunk and block edges, at every anisotropic tap.
#include "shadel/shadel.glsl"

layout(early_fragment_tests) in;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint shadowView;
} pc;

layout(location = 4) flat in uint inInstance;
layout(location = 5) in vec2 inShadelUv;

void markChunk(ShadelFrame s, uvec2 sheet) {
    uint block = blockIndex(s, sheet);
    uint64_t bit = 1ul << chunkBit(sheet);
    Uint64Buffer occupancy = Uint64Buffer(s.occupancy);
    // Most pixels find their chunk already marked: skip the atomic then.
    if ((occupancy.v[block] & bit) == 0ul) atomicOr(occupancy.v[block], bit);
}

void markLevel(ShadelFrame s, GpuShadelObject o, uint mip, vec2 uv) {
    ivec2 t0;
    vec2 w;
    bilinearFootprint(o, mip, uv, t0, w);
    uvec2 a = sheetShadel(o, mip, t0);
    uvec2 b = sheetShadel(o, mip, t0 + ivec2(1));
    // The four taps span at most 2x2 chunks; mark each distinct one.
    markChunk(s, a);
    if (b.x / SHADEL_CHUNK != a.x / SHADEL_CHUNK) markChunk(s, uvec2(b.x, a.y));
    if (b.y / SHADEL_CHUNK != a.y / SHADEL_CHUNK) markChunk(s, uvec2(a.x, b.y));
    if (b.x / SHADEL_CHUNK != a.x / SHADEL_CHUNK && b.y / SHADEL_CHUNK != a.y / SHADEL_CHUNK) markChunk(s, b);
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    GpuShadelObject o = ShadelObjectBuffer(s.objects).o[inInstance];
    vec2 texel = inShadelUv * vec2(o.mip0Size);
    vec2 dx = dFdx(texel), dy = dFdy(texel);
    ShadelLevels l = shadelLevels(o, dx, dy, s.shadingBias, s.trilinearBand);
    ShadelAniso a = shadelAniso(dx, dy);
    for (uint i = 0u; i < a.taps; ++i) {
        vec2 uv = shadelTapUv(o.mip0Size, inShadelUv, a, i);
        markLevel(s, o, l.mip0, uv);
        if (l.two) markLevel(s, o, l.mip1, uv);
    }
}
