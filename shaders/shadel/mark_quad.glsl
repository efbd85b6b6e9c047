// Compute marking's per-quad code (--marking visibility), shared by its three passes:
// mark_visibility.comp marks the quads whose four pixels see one decoupled triangle without
// per-pixel branches (markQuadOnTriangles) and lists the others; mark_two_triangles.comp marks
// the listed quads whose pixels see two triangles of one decoupled instance the same way; and
// mark_listed.comp marks the rest pixel by pixel (markQuadPixel). All give every pixel the
// same chunks and reconstruction address.
// Why three passes: on lavapipe a SIMD group runs the code of a branch whenever any of its lanes
// takes it. 1 - 0.85^8 of 8-quad groups hold a quad that is not on one triangle, so in one pass
// nearly every group ran the per-pixel code, and a second triangle's setup, for all eight.
// markingCompute, alternating runs, builtin:default 1280x720 orbit: 51.1, 51.2 -> 38.7, 39.7 ms
// with two passes. Of the 35,016 quads the first pass lists there, 26,294 see two triangles of
// one instance (a triangle edge crosses them), and 90% of those have the same levels on both:
// the second pass marks them without the per-pixel code and lists the others for the third,
// which also takes every other quad the first pass could not mark (sky or forward edges, two
// instances, three triangles, the screen's last row or column, level-window fallbacks).
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

// The quads the first pass leaves to the later two, and their indirect arguments
// (mark_listed_args.comp). Two lists of a slot per quad of the screen each: the two-triangle
// quads (mark_two_triangles.comp) in the first, the per-pixel ones (mark_listed.comp) in the
// second. The second pass appends to the second list while it reads the first, so they cannot
// share one array: a quad goes to the first list or, from the first pass or the second, to the
// second, so each holds at most every quad once.
layout(buffer_reference, scalar) buffer MarkQuadList {
    uvec4 twoTriangleDispatch; // x, y, z, count
    uvec4 pixelDispatch;       // x, y, z, count
    uint twoTriangleCount;
    uint pixelCount;
    uint pad0, pad1;
    uint quads[]; // origin x | y << 16: the two-triangle list, then the per-pixel list
};

uint markQuadCapacity() { return ((pc.width + 1u) >> 1) * ((pc.height + 1u) >> 1); }

uint packQuadOrigin(ivec2 origin) { return uint(origin.x) | (uint(origin.y) << 16); }
ivec2 unpackQuadOrigin(uint packed) { return ivec2(packed & 0xFFFFu, packed >> 16); }

// Appends this invocation's quad to the two-triangle or the per-pixel list: one atomic per
// subgroup and list. Every invocation of the subgroup must call it.
void listMarkQuad(ivec2 origin, bool twoTriangles, bool pixels) {
    MarkQuadList list = MarkQuadList(pc.markList);
    uvec4 front = subgroupBallot(twoTriangles);
    uvec4 back = subgroupBallot(pixels);
    uint frontCount = subgroupBallotBitCount(front), backCount = subgroupBallotBitCount(back);
    if (frontCount + backCount == 0u) return;
    uvec2 first = uvec2(0u);
    if (subgroupElect()) {
        if (frontCount != 0u) first.x = atomicAdd(list.twoTriangleCount, frontCount);
        if (backCount != 0u) first.y = atomicAdd(list.pixelCount, backCount);
    }
    first = subgroupBroadcastFirst(first);
    if (twoTriangles) list.quads[first.x + subgroupBallotExclusiveBitCount(front)] = packQuadOrigin(origin);
    if (pixels)
        list.quads[markQuadCapacity() + first.y + subgroupBallotExclusiveBitCount(back)] =
            packQuadOrigin(origin);
}

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

// One pixel of a quad, marked on its own: its footprints, marked and written as its
// reconstruction address. The pixel sets up its triangle over the quad (its coarse
// derivatives are the quad's on that triangle), as the other passes set up theirs.
void markQuadPixel(FrameConstants f, ShadelFrame s, ivec2 origin, int i, uvec2 vis) {
    ivec2 pixel = origin + ivec2(i & 1, i >> 1);
    if (pixel.x >= int(pc.width) || pixel.y >= int(pc.height)) return;
    uvec4 address = resolveAddressNone();
    if (vis.x != VISIBILITY_NONE) {
        QuadTriangle t = setUpQuad(f, s, vis, origin);
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

// Marks a quad whose four pixels see one or two triangles of one decoupled instance at the same
// levels (ta's and tb's: the pixels with bit i of onB set see tb) without per-pixel branches:
// the chunks and addresses markQuadPixel would give its pixels. Each pixel takes its own
// triangle's shadel UV, MIP blend and magnification. False (nothing marked nor written) where
// the quad needs the per-pixel code: the triangles' levels differ, or quadLevel fails.
bool markQuadOnTriangles(ShadelFrame s, QuadTriangle ta, QuadTriangle tb, uint onB, ivec2 origin) {
    // (one tap since the anisotropy cap: shadelAniso)
    if (ta.aniso.taps != 1u || tb.aniso.taps != 1u) return false;
    if (ta.levels.mip0 != tb.levels.mip0 || ta.levels.mip1 != tb.levels.mip1 ||
        ta.levels.two != tb.levels.two)
        return false;
    vec2 uv[4];
    for (int i = 0; i < 4; ++i) {
        vec2 a = visInterpolate(ta.q.bary[i], ta.q.uv0, ta.q.uv1, ta.q.uv2);
        vec2 b = visInterpolate(tb.q.bary[i], tb.q.uv0, tb.q.uv1, tb.q.uv2);
        uv[i] = ((onB >> i) & 1u) != 0u ? b : a; // (visShadelSample's shadelUv)
    }
    QuadLevel level0, level1;
    if (!quadLevel(ta.o, ta.levels.mip0, uv, level0)) return false;
    if (ta.levels.two && !quadLevel(ta.o, ta.levels.mip1, uv, level1)) return false;
    markQuadLevel(s, level0);
    if (ta.levels.two) markQuadLevel(s, level1);
    // As reconstructSample counts magnification: from each triangle's (coarse) derivatives.
    vec2 dx = ta.first.texelDx, dy = ta.first.texelDy;
    bool magnifiedA = max(dot(dx, dx), dot(dy, dy)) < 1.0;
    dx = tb.first.texelDx;
    dy = tb.first.texelDy;
    bool magnifiedB = max(dot(dx, dx), dot(dy, dy)) < 1.0;
    MarkedSample m;
    m.windowFallback = false;
    m.forward = false;
    m.taps = 1u;
    uint first = resolveAddressIndex(origin, pc.width); // the quad's four, in pixel order
    for (int i = 0; i < 4; ++i) {
        bool b = ((onB >> i) & 1u) != 0u;
        m.levels = b ? tb.levels : ta.levels;
        m.footprint0 = level0.pixel[i];
        m.footprint1 = ta.levels.two ? level1.pixel[i] : level0.pixel[i];
        ResolveAddressBuffer(pc.addresses).v[first + uint(i)] =
            packResolveAddress(m, b ? magnifiedB : magnifiedA);
    }
    return true;
}
#endif
