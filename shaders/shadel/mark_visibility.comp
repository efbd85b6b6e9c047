#version 460
// Compute marking (--marking visibility): one invocation per 2x2 quad of the visibility
// buffer. Pixels of decoupled instances rebuild their shadel UV and its screen derivatives from
// the triangle and the pixel ray (shadel/vis_shadel.glsl), mark what the resolve will read and
// write it down for the resolve: the pixel's reconstruction address (shadel/resolve_address.glsl).
//
// A quad's setup (the triangle's vertices, the four pixels' barycentrics) serves every pixel of
// the quad on that triangle: one for its first covered pixel's triangle, one for the first other
// triangle, and a pixel on a third triangle sets up its own. On lavapipe a SIMD group runs the
// code of a branch whenever any of its lanes takes it, so the earlier form, a setup in the pixel
// loop whenever the triangle changed, cost four setups per quad. Of builtin:default's covered
// quads at 1280x720, 85% see one triangle, 13% two and 2% more. markingCompute, alternating
// runs, 1280x720 orbit: 22.9-23.4 -> 21.2-21.9 ms; 1920x1080: 49.8 -> 47.5-48.5 (images
// identical).
// The quad's derivatives are coarse (shadel/vis_shadel.glsl), so its pixels of one triangle share
// their MIP levels and anisotropy, taken once with the setup: markingCompute, alternating runs,
// 1280x720 orbit 21.7, 21.7, 20.9 -> 21.6, 19.8, 19.4 ms; 1920x1080 45.4, 45.0, 44.7 -> 41.4,
// 42.2, 41.3 ms (the same shadels shaded: 880,640 -> 880,448 at 1920x1080).
#define SHADEL_MARK_CACHE // the quad's pixels mostly mark the same chunks: skip repeats
#include "shadel/resolve_address.glsl"
#include "shadel/vis_shadel.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint visibilitySlot;
    uint width;
    uint height;
    uint hdrSlot; // (the resolve's)
    uint64_t addresses; // ResolveAddressBuffer
} pc;

// The quad's pixels on one triangle: its setup and, from the quad's coarse derivatives, the MIP
// levels and anisotropy they all share (decoupled instances only; else unused).
struct QuadTriangle {
    ShadelObjectRef o;
    VisQuad q;
    bool decoupled;
    ShadelLevels levels;
    ShadelAniso aniso;
};

// The setup of the quad's pixels on `vis`'s triangle (a covered pixel's).
QuadTriangle setUpQuad(FrameConstants f, ShadelFrame s, uvec2 vis, ivec2 origin) {
    QuadTriangle t;
    t.o = shadelObject(s, vis.x);
    t.decoupled = (t.o.v.flags & SHADEL_OBJECT_DECOUPLED) != 0u;
    uvec2 any = t.decoupled ? vis : uvec2(vis.x, 0u); // a valid triangle to set up (unused if not)
    visQuadSetup(f, s, InstanceBuffer(f.instances).i[any.x], any.y, origin, t.q);
    VisShadel v = visShadelSample(t.q, t.o, 0); // (every pixel's derivatives are these)
    t.levels = shadelLevels(t.o, v.texelDx, v.texelDy, s.shadingBias, s.trilinearBand);
    t.aniso = shadelAniso(v.texelDx, v.texelDy);
    return t;
}

void main() {
    ivec2 origin = ivec2(gl_GlobalInvocationID.xy) * 2;
    if (origin.x >= int(pc.width) || origin.y >= int(pc.height)) return;
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    uvec2 vis[4];
    for (int i = 0; i < 4; ++i) {
        ivec2 pixel = origin + ivec2(i & 1, i >> 1);
        bool inside = pixel.x < int(pc.width) && pixel.y < int(pc.height);
        vis[i] = inside ? loadVisibility(pc.visibilitySlot, pixel) : uvec2(VISIBILITY_NONE);
    }
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
        // A branch, but most SIMD groups take it: 1 - 0.85^8 of 8-quad groups hold a mixed quad.
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
            if (t.decoupled) { // else a forward (hybrid) instance
                VisShadel v = visShadelSample(t.q, t.o, i);
                MarkedSample m = markSampleWith(s, t.o, v.shadelUv, t.levels, t.aniso);
                // As reconstructSample counts magnification (only sampled pixels count it).
                bool magnified = max(dot(v.texelDx, v.texelDx), dot(v.texelDy, v.texelDy)) < 1.0;
                address = packResolveAddress(m, magnified);
            }
        }
        ResolveAddressBuffer(pc.addresses).v[resolveAddressIndex(pixel, pc.width)] = address;
    }
}
