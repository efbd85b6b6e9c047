// The compute resolve's per-pixel code, shared by the resolve (resolve.comp: the addressed
// pixels) and the rebuild pass (resolve_rebuild.comp: the rare pixels the resolve lists).
#ifndef SHADEL_RESOLVE_PIXEL_GLSL
#define SHADEL_RESOLVE_PIXEL_GLSL
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "shadel/resolve.glsl"
#include "shadel/resolve_address.glsl"
#include "shadel/vis_shadel.glsl"
#include "common/lighting.glsl"
#include "common/vertex.glsl"
#include "common/tone_curve.glsl"
#include "background/background.glsl"
#include "debug/inspect_shadel.glsl"

// The pixels the resolve leaves to the rebuild pass, and that pass's indirect arguments.
layout(buffer_reference, scalar) buffer ResolveRebuildList {
    uvec4 dispatch; // x, y, z (resolve_rebuild_args.comp)
    uint count;
    uint pad0, pad1, pad2;
    uint pixels[]; // x | y << 16
};

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint visibilitySlot;
    uint width;
    uint height;
    uint hdrSlot;
    uint64_t addresses;   // ResolveAddressBuffer
    uint64_t rebuildList; // ResolveRebuildList
    uint64_t markList;    // (the marking's)
    uint64_t displayPixels; // the readback's RGBA8 pixels (kDisplayOutput)
} pc;

// The frame's tonemap fused into the resolve (render/post/tonemap.h): display pixels into the
// readback (pc.displayPixels), else scene colour into the HDR target.
layout(constant_id = RESOLVE_DISPLAY_OUTPUT_CONSTANT_ID) const bool kDisplayOutput = false;

// The resolve's output: the pixel's scene colour (alpha: covered), or its display pixel.
void writeResolvedPixel(FrameConstants f, ivec2 pixel, vec4 color) {
    if (kDisplayOutput)
        UintBuffer(pc.displayPixels).v[pixel.y * int(pc.width) + pixel.x] =
            packDisplayPixel(displayColor(color.rgb, f.exposure, f.tonemap), color.a > 0.0);
    else
        imageStore(gImagesRgba16f[pc.hdrSlot], pixel, color);
}

// The forward material + lighting at the pixel, from the triangle's interpolated attributes
// (what the forward raster pass's varyings and dFdx/dFdy would give).
vec3 forwardShade(FrameConstants f, GpuInstance inst, VisTriangle tri, VisBary bary,
                  uvec2 vis, ivec2 pixel, bool inspect) {
    GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
    WorldVertex a = fetchWorldVertex(f, inst, tri.v0);
    WorldVertex b = fetchWorldVertex(f, inst, tri.v1);
    WorldVertex c = fetchWorldVertex(f, inst, tri.v2);
    vec3 w = bary.center;
    SurfaceInput si;
    si.position = visInterpolate(w, a.position, b.position, c.position);
    si.normal = normalize(visInterpolate(w, a.normal, b.normal, c.normal));
    si.tangent = visInterpolate(w, a.tangent, b.tangent, c.tangent);
    si.uv = visInterpolate(w, a.uv0, b.uv0, c.uv0);
    si.uvDx = visInterpolate(bary.dx, a.uv0, b.uv0, c.uv0);
    si.uvDy = visInterpolate(bary.dy, a.uv0, b.uv0, c.uv0);
    si.uv1 = visInterpolate(w, a.uv1, b.uv1, c.uv1);
    si.uv1Dx = visInterpolate(bary.dx, a.uv1, b.uv1, c.uv1);
    si.uv1Dy = visInterpolate(bary.dy, a.uv1, b.uv1, c.uv1);
    si.frontFacing = tri.frontFacing;
    MaterialSample m = evaluateMaterial(mat, si);
    // The lights as forward shading culls them (a tile's list, or the light grid's candidates
    // at the point): a fallback pixel must not loop over every light of the scene.
    useLightListAt(f, vec2(pixel) + 0.5, si.position);
    vec3 color = shadeSurface(f, m, si.position, si.normal);
    if (inspect) inspectSurface(f, vis.x, vis.y, m, si.position, si.normal, color);
    return color;
}

// The filter over the footprints marking addressed; missing/overflowed count the lookups that
// found no storage (the pixel is then rebuilt and shaded forward). Always the radiance layer:
// the debug views (--visualize layer:material among them) take the rebuilt path, so the taps'
// layer is a constant here.
vec3 resolveAddressed(ShadelFrame s, ResolveAddress a, inout uint missing, inout uint overflowed) {
    const uint layer = SHADEL_LAYER_RADIANCE;
    uint64_t mask;
    int slot;
    vec3 c = sampleFootprint(s, a.footprint0, layer, missing, overflowed, mask, slot);
    if (a.two)
        c = mix(c, sampleFootprint(s, a.footprint1, layer, missing, overflowed, mask, slot), a.blend);
    return c;
}

// The pixel rebuilt from the visibility buffer: the sample, the reconstruction with its debug
// views and inspection, and the forward shading of misses and overflow. The quad's setup is
// shared by its pixels of the same triangle (current, o, inst, q).
vec4 resolveRebuilt(FrameConstants f, ShadelFrame s, ivec2 origin, int i, ivec2 pixel,
                    inout uvec2 current, inout ShadelObjectRef o, inout GpuInstance inst,
                    inout VisQuad q, inout uvec4 counts) {
    uvec2 vis = loadVisibility(pc.visibilitySlot, pixel);
    if (vis.x == VISIBILITY_NONE) return vec4(backgroundAt(f, vec2(pixel) + 0.5), 0.0);
    if (vis != current) {
        current = vis;
        o = shadelObject(s, vis.x);
        if ((o.v.flags & SHADEL_OBJECT_DECOUPLED) != 0u) {
            inst = InstanceBuffer(f.instances).i[vis.x];
            visQuadSetup(f, s, inst, vis.y, origin, q);
        }
    }
    if ((o.v.flags & SHADEL_OBJECT_DECOUPLED) == 0u) return vec4(f.skyColor, 0.0);
    VisShadel v = visShadelSample(q, o, i);
    Reconstruction r = reconstructSample(s, o, v.shadelUv, v.texelDx, v.texelDy, pixel,
                                         reconstructionLayer(f, s));
    counts += uvec4(r.magnified ? 1u : 0u, r.sampled ? 1u : 0u, r.missing != 0u ? 1u : 0u,
                    r.overflowed != 0u ? 1u : 0u);
    if (r.sampled && r.windowFallback) // rare: only where a window lags the view
        atomicAdd(ShadelCountersRef(s.counters).c.windowFallbackPixels, 1u);
    if (r.sampled && r.forward) // rarer: lagging by more than a level (a camera cut)
        atomicAdd(ShadelCountersRef(s.counters).c.windowForwardPixels, 1u);
    vec3 c = r.color;
    bool shadeForward = r.missing + r.overflowed != 0u || r.forward;
    bool inspect = inspecting(f, uvec2(pixel));
    if (inspect) {
        vec4 clip = f.viewProj * vec4(visInterpolate(v.bary.center,
            fetchWorldVertex(f, inst, q.tri.v0).position,
            fetchWorldVertex(f, inst, q.tri.v1).position,
            fetchWorldVertex(f, inst, q.tri.v2).position), 1.0);
        beginInspect(f, vis.x, vis.y, vec4(vec2(pixel) + 0.5, clip.z / clip.w, 1.0));
        inspectShadels(f, s, o, r, v.shadelUv, v.texelDx, v.texelDy);
    }
    if (shadeForward || inspect) {
        useTileDecalList(f, vec2(pixel) + 0.5); // decals, as forward shading applies them
        vec3 forward = forwardShade(f, inst, q.tri, v.bary, vis, pixel, inspect);
        if (shadeForward) c = forward;
    }
    if (inspect) shaderPrintF3(f, PRINT_OUTPUT, c);
    return vec4(visualizeReconstruction(f, o, r, c, v.shadelUv, v.texelDx, v.texelDy), 1.0);
}

// The resolve's counts summed over the subgroup, one atomic each (no shared sums: their barriers
// cost more than the atomics where a workgroup's invocations run in turn, lavapipe). Any
// control flow where whole subgroups arrive (the end of main).
void countResolvedPixels(ShadelFrame s, uvec4 counts) {
    counts = subgroupAdd(counts);
    if (subgroupElect()) {
        ShadelCountersRef counters = ShadelCountersRef(s.counters);
        if (counts.x != 0u) atomicAdd(counters.c.magnifiedPixels, counts.x);
        if (counts.y != 0u) atomicAdd(counters.c.reconstructedPixels, counts.y);
        if (counts.z != 0u) atomicAdd(counters.c.reconstructionMisses, counts.z);
        if (counts.w != 0u) atomicAdd(counters.c.overflowSamples, counts.w);
    }
}
#endif
