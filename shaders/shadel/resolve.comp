#version 460
// Compute resolve (--marking visibility): one invocation per 2x2 quad of pixels. A decoupled
// pixel reads the reconstruction address the compute marking wrote (shadel/resolve_address.glsl:
// the footprints of the levels it marked) and does only the chunk lookups, the storage fetches
// and the filter of the raster reconstruction (shadel/resolve.glsl). The debug views,
// --inspect, misses, overflow and camera-cut samples rebuild the sample from the visibility
// buffer instead (shadel/resolve_pixel.glsl resolveRebuilt: the same samples as the marking;
// misses, overflow and cuts are shaded forward from the rebuilt attributes). Pixels of forward
// (hybrid) instances were drawn by the raster pass before (hybridForward) and are left as it drew
// them; every other pixel gets the sky.
//
// With the frame's tonemap fused into the resolve (kDisplayOutput, render/post/tonemap.h) every
// pixel is written as the display shows it, into the readback, forward ones read from the scene
// colour: no scene colour is stored and no tonemap pass runs. (1280x720 on lavapipe: the tone
// curve costs the resolve about 1.5 ms more than storing scene colour; the tonemap pass cost 13.)
//
// Without debug views or --inspect the rebuild is not compiled in (kRebuildInline false): the
// resolve lists those rare pixels and resolve_rebuild.comp shades them by indirect dispatch.
// Where a SIMD group runs code none of its lanes takes (lavapipe), the inline rebuild and its
// forward shading cost every quad: resolveCompute 21.7 ms -> 15.3 ms without it (1280x720).
#include "shadel/resolve_pixel.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(constant_id = RESOLVE_REBUILD_INLINE_CONSTANT_ID) const bool kRebuildInline = true;

void resolveQuad(FrameConstants f, ShadelFrame s, ivec2 origin, inout uvec4 counts) {
    uvec2 current = uvec2(VISIBILITY_NONE);
    VisQuad q;
    ShadelObjectRef o;
    GpuInstance inst;
    for (int i = 0; i < 4; ++i) {
        ivec2 pixel = origin + ivec2(i & 1, i >> 1);
        if (pixel.x >= int(pc.width) || pixel.y >= int(pc.height)) continue;
        ResolveAddress a = unpackResolveAddress(
            ResolveAddressBuffer(pc.addresses).v[resolveAddressIndex(pixel, pc.width)]);
        // A forward (hybrid) pixel: hybridForward drew it into the scene colour, which holds it
        // unless the display pixel is written here. Its colour then goes through the one write
        // below: lavapipe runs a branch's code for every lane, so a write of its own would cost
        // every pixel a second tone curve.
        bool forward = a.kind == RESOLVE_ADDRESS_FORWARD;
        if (forward && !kDisplayOutput) continue;
        vec4 color = vec4(0.0);
        if (a.kind == RESOLVE_ADDRESS_NONE) color.rgb = backgroundAt(f, vec2(pixel) + 0.5);
        if (forward) color = vec4(imageLoad(gImagesRgba16f[pc.hdrSlot], pixel).rgb, 1.0);
        bool rebuild = !forward && (a.kind == RESOLVE_ADDRESS_REBUILD ||
                                    f.visualize != VISUALIZE_NONE || inspecting(f, uvec2(pixel)));
        if (a.kind == RESOLVE_ADDRESS_READY && !rebuild) {
            uint missing = 0u, overflowed = 0u;
            vec3 c = resolveAddressed(s, a, missing, overflowed);
            if (missing + overflowed == 0u) {
                bool sampled = all(equal(pixel & 1, ivec2(0))); // as reconstructSample samples
                counts += uvec4(sampled && a.magnified ? 1u : 0u, sampled ? 1u : 0u, 0u, 0u);
                if (sampled && a.windowFallback)
                    atomicAdd(ShadelCountersRef(s.counters).c.windowFallbackPixels, 1u);
                color = vec4(c, 1.0);
            } else {
                rebuild = true; // rare: shaded forward from the rebuilt attributes
            }
        }
        if (rebuild && !kRebuildInline) { // listed for the rebuild pass, which writes it
            ResolveRebuildList list = ResolveRebuildList(pc.rebuildList);
            list.pixels[atomicAdd(list.count, 1u)] = uint(pixel.x) | (uint(pixel.y) << 16);
            continue;
        }
        if (rebuild && kRebuildInline)
            color = resolveRebuilt(f, s, origin, i, pixel, current, o, inst, q, counts);
        writeResolvedPixel(f, pixel, color);
    }
}

void main() {
    ivec2 origin = ivec2(gl_GlobalInvocationID.xy) * 2;
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    uvec4 counts = uvec4(0u);
    if (origin.x < int(pc.width) && origin.y < int(pc.height)) resolveQuad(f, s, origin, counts);
    countResolvedPixels(s, counts);
}
