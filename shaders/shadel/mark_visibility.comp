#version 460
// Compute marking (--marking visibility): one invocation per 2x2 quad of the visibility
// buffer. Pixels of decoupled instances rebuild their shadel UV and its screen derivatives from
// the triangle and the pixel ray (shadel/vis_shadel.glsl), mark what the resolve will read and
// write it down for the resolve: the pixel's reconstruction address (shadel/resolve_address.glsl).
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

void main() {
    ivec2 origin = ivec2(gl_GlobalInvocationID.xy) * 2;
    if (origin.x >= int(pc.width) || origin.y >= int(pc.height)) return;
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    uvec2 current = uvec2(VISIBILITY_NONE);
    VisQuad q;
    ShadelObjectRef o;
    for (int i = 0; i < 4; ++i) {
        ivec2 pixel = origin + ivec2(i & 1, i >> 1);
        if (pixel.x >= int(pc.width) || pixel.y >= int(pc.height)) continue;
        uvec4 address = resolveAddressNone();
        uvec2 vis = loadVisibility(pc.visibilitySlot, pixel);
        if (vis.x != VISIBILITY_NONE) {
            if (vis != current) {
                current = vis;
                o = shadelObject(s, vis.x);
                if ((o.v.flags & SHADEL_OBJECT_DECOUPLED) != 0u)
                    visQuadSetup(f, s, InstanceBuffer(f.instances).i[vis.x], vis.y, origin,
                                 q);
            }
            if ((o.v.flags & SHADEL_OBJECT_DECOUPLED) != 0u) { // else a forward (hybrid) instance
                VisShadel v = visShadelSample(q, o, i);
                MarkedSample m = markSample(s, o, v.shadelUv, v.texelDx, v.texelDy);
                // As reconstructSample counts magnification (only sampled pixels count it).
                bool magnified = max(dot(v.texelDx, v.texelDx), dot(v.texelDy, v.texelDy)) < 1.0;
                address = packResolveAddress(m, magnified);
            }
        }
        ResolveAddressBuffer(pc.addresses).v[resolveAddressIndex(pixel, pc.width)] = address;
    }
}
