// Compute marking's per-quad code (--marking visibility), shared by its two passes:
// mark_visibility.comp marks the quads whose four pixels see one decoupled triangle without
// per-pixel branches (markWholeQuad) and lists the others, which mark_listed.comp marks pixel
// by pixel (markQuadPixels). Both give every pixel the same chunks and reconstruction address.
// Why two passes: on lavapipe a SIMD group runs the code of a branch whenever any of its lanes
// takes it, and 1 - 0.85^8 of 8-quad groups hold a quad that is not on one triangle, so in one
// pass nearly every group ran the per-pixel code, and a second triangle's setup, for all eight.
// markingCompute, alternating runs, builtin:default 1280x720 orbit: 51.1, 51.2 -> 38.7, 39.7 ms,
// the images byte-identical.
#ifndef SHADEL_MARK_QUAD_GLSL
#define SHADEL_MARK_QUAD_GLSL
#define SHADEL_MARK_CACHE // the quad's pixels mostly mark the same chunks: skip repeats
#extension GL_KHR_shader_subgroup_ballot : require
#include "shadel/resolve_address.glsl"
#include "shadel/vis_shadel.glsl"

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint visibilitySlot;
    uint width;
    uint height;
    uint hdrSlot;         // (the resolve's)
    uint64_t addresses;   // ResolveAddressBuffer
    uint64_t rebuildList; // (the resolve's)
    uint64_t markList;    // MarkQuadList
} pc;

// The quads the first pass leaves to the second (mark_listed.comp), and its indirect arguments.
layout(buffer_reference, scalar) buffer MarkQuadList {
    uvec4 dispatch; // x, y, z (mark_listed_args.comp)
    uint count;
    uint pad0, pad1, pad2;
    uint quads[]; // origin x | y << 16
};

// The quad's pixels on one triangle: its setup and, from the quad's coarse derivatives, the MIP
// levels and anisotropy they all share (decoupled instances only; else unused).
struct QuadTriangle {
    ShadelObjectRef o;
    VisQuad q;
    bool decoupled;
    ShadelLevels levels;
    ShadelAniso aniso;
    VisShadel first; // pixel (0,0)'s sample: its UV, the quad's derivatives
};

// The setup of the quad's pixels on `vis`'s triangle (a covered pixel's).
QuadTriangle setUpQuad(FrameConstants f, ShadelFrame s, uvec2 vis, ivec2 origin) {
    QuadTriangle t;
    t.o = shadelObject(s, vis.x);
    t.decoupled = (t.o.v.flags & SHADEL_OBJECT_DECOUPLED) != 0u;
    uvec2 any = t.decoupled ? vis : uvec2(vis.x, 0u); // a valid triangle to set up (unused if not)
    visQuadSetup(f, s, InstanceBuffer(f.instances).i[any.x], any.y, origin, t.q);
    t.first = visShadelSample(t.q, t.o, 0); // (every pixel's derivatives are these)
    t.levels = shadelLevels(t.o, t.first.texelDx, t.first.texelDy, s.shadingBias, s.trilinearBand);
    t.aniso = shadelAniso(t.first.texelDx, t.first.texelDy);
    return t;
}

void loadQuadVisibility(ivec2 origin, out uvec2 vis[4]) {
    for (int i = 0; i < 4; ++i) {
        ivec2 pixel = origin + ivec2(i & 1, i >> 1);
        bool inside = pixel.x < int(pc.width) && pixel.y < int(pc.height);
        vis[i] = inside ? loadVisibility(pc.visibilitySlot, pixel) : uvec2(VISIBILITY_NONE);
    }
}

// The pixel-by-pixel marking of a quad: each pixel's own footprints, marked and written as its
// reconstruction address. A quad's setup (the triangle's vertices, the four pixels'
// barycentrics) serves every pixel of the quad on that triangle: one for its first covered
// pixel's triangle, one for the first other triangle, and a pixel on a third triangle sets up
// its own.
void markQuadPixels(FrameConstants f, ShadelFrame s, ivec2 origin, uvec2 vis[4]) {
    // The quad's first covered triangle (a), and the first other one (b; a when there is none).
    uvec2 a = vis[0];
    for (int i = 1; i < 4; ++i) a = a.x == VISIBILITY_NONE ? vis[i] : a;
    uvec2 b = a;
    for (int i = 3; i > 0; --i) b = vis[i].x != VISIBILITY_NONE && vis[i] != a ? vis[i] : b;
    QuadTriangle ta, tb;
    ta.decoupled = false;
    tb.decoupled = false;
    if (a.x != VISIBILITY_NONE) { // (a sky quad sets up nothing, nor reads, in an empty scene)
        ta = setUpQuad(f, s, a, origin);
        tb = b != a ? setUpQuad(f, s, b, origin) : ta;
    }
    for (int i = 0; i < 4; ++i) {
        ivec2 pixel = origin + ivec2(i & 1, i >> 1);
        if (pixel.x >= int(pc.width) || pixel.y >= int(pc.height)) continue;
        uvec4 address = resolveAddressNone();
        if (vis[i].x != VISIBILITY_NONE) {
            bool onA = vis[i] == a;
            QuadTriangle t = onA ? ta : tb;
            if (!onA && vis[i] != b) t = setUpQuad(f, s, vis[i], origin); // a third (rare)
            if (t.decoupled) {
                VisShadel v = visShadelSample(t.q, t.o, i);
                MarkedSample m = markSampleWith(s, t.o, v.shadelUv, t.levels, t.aniso);
                // As reconstructSample counts magnification (only sampled pixels count it).
                bool magnified = max(dot(v.texelDx, v.texelDx), dot(v.texelDy, v.texelDy)) < 1.0;
                address = packResolveAddress(m, magnified);
            } else {
                address = resolveAddressForward();
            }
        }
        ResolveAddressBuffer(pc.addresses).v[resolveAddressIndex(pixel, pc.width)] = address;
    }
}

// A quad whose four pixels see one decoupled triangle at the same levels (coarse derivatives)
// needs no per-pixel branches: its pixels' footprints at `mip` (what markSampleWith and
// fitLevelFootprints take for each pixel) and the chunks they read, which lie in a 2x2 box of
// chunks: `chunks` has bit x + 2y for each chunk of the box some pixel reads (an L of three is
// common where the footprints straddle both chunk edges), `first` is a sheet shadel of the box's
// first chunk. False where the quad needs the per-pixel code: the level's window does not hold
// every footprint (a rare fallback, per pixel), or they span more than two chunks on an axis.
struct QuadLevel {
    LevelFootprint pixel[4];
    uvec2 first;
    uint chunks;
};

bool quadLevel(ShadelObjectRef o, uint mip, vec2 uv[4], out QuadLevel q) {
    ivec2 t0[4];
    for (int i = 0; i < 4; ++i) bilinearFootprint(o, mip, uv[i], t0[i], q.pixel[i].weight);
    ivec2 lo = min(min(t0[0], t0[1]), min(t0[2], t0[3]));
    ivec2 hi = max(max(t0[0], t0[1]), max(t0[2], t0[3]));
    uvec2 a = levelTexel(o, mip, lo), b = levelTexel(o, mip, hi + ivec2(1));
    uvec4 rect = o.v.rect[mip];
    uvec2 origin = windowOrigin(o, mip);
    bool held = all(greaterThanEqual(a, origin)) && all(lessThan(b, origin + rect.zw * SHADEL_BLOCK));
    uvec2 base = a / SHADEL_CHUNK;
    if (!held || any(greaterThan(b / SHADEL_CHUNK - base, uvec2(1u)))) return false;
    uvec2 offset = rect.xy * SHADEL_BLOCK - origin; // level texel -> sheet shadel (sheetShadel)
    q.first = offset + base * SHADEL_CHUNK;
    q.chunks = 0u;
    for (int i = 0; i < 4; ++i) {
        uvec2 lo = levelTexel(o, mip, t0[i]), hi = levelTexel(o, mip, t0[i] + ivec2(1));
        q.pixel[i].lo = offset + lo;
        q.pixel[i].hi = offset + hi;
        uvec2 c0 = lo / SHADEL_CHUNK - base, c1 = hi / SHADEL_CHUNK - base; // 0 or 1 per axis
        q.chunks |= (1u << (c0.x + 2u * c0.y)) | (1u << (c1.x + 2u * c0.y)) |
                    (1u << (c0.x + 2u * c1.y)) | (1u << (c1.x + 2u * c1.y));
    }
    return true;
}

void markQuadLevel(ShadelFrame s, QuadLevel q) {
    for (uint k = 0u; k < 4u; ++k)
        if ((q.chunks & (1u << k)) != 0u) markChunk(s, q.first + uvec2(k & 1u, k >> 1u) * SHADEL_CHUNK);
}

// Marks a quad whose four pixels all see triangle t (decoupled) without per-pixel branches: the
// chunks and addresses markQuadPixels would give it. False (nothing marked nor written) where
// the quad needs the per-pixel code (quadLevel).
bool markWholeQuad(ShadelFrame s, QuadTriangle t, ivec2 origin) {
    if (t.aniso.taps != 1u) return false; // (one tap since the anisotropy cap: shadelAniso)
    vec2 uv[4];
    uv[0] = t.first.shadelUv;
    for (int i = 1; i < 4; ++i) uv[i] = visShadelSample(t.q, t.o, i).shadelUv;
    QuadLevel level0, level1;
    if (!quadLevel(t.o, t.levels.mip0, uv, level0)) return false;
    if (t.levels.two && !quadLevel(t.o, t.levels.mip1, uv, level1)) return false;
    markQuadLevel(s, level0);
    if (t.levels.two) markQuadLevel(s, level1);
    vec2 dx = t.first.texelDx, dy = t.first.texelDy;
    bool magnified = max(dot(dx, dx), dot(dy, dy)) < 1.0; // as reconstructSample counts it
    MarkedSample m;
    m.levels = t.levels;
    m.windowFallback = false;
    m.forward = false;
    m.taps = 1u;
    uint first = resolveAddressIndex(origin, pc.width); // the quad's four, in pixel order
    for (int i = 0; i < 4; ++i) {
        m.footprint0 = level0.pixel[i];
        m.footprint1 = t.levels.two ? level1.pixel[i] : level0.pixel[i];
        ResolveAddressBuffer(pc.addresses).v[first + uint(i)] = packResolveAddress(m, magnified);
    }
    return true;
}
#endif
