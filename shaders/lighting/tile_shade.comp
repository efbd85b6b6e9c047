#version 460
// Tile shading with feature spectra, forward mode with --spectra on|single: one
// 16x16 workgroup per light tile of this pipeline's bin (an indirect dispatch per mode). The
// pipeline is one permutation: kSpectrumFeatures (shaders/common/lighting.glsl) holds only
// the features of its mode, so what its tiles do not need is not compiled in. Each pixel
// rebuilds its surface from the visibility buffer (instance, triangle) exactly as the raster
// forward pass's varyings and dFdx/dFdy give it (shaders/common/visibility.glsl), then runs
// the same evaluateMaterial + shadeSurface over its tile's light list.
#include "common/lighting.glsl"
#include "common/vertex.glsl"
#include "common/visibility.glsl"
#include "lighting/light_debug.glsl"
#include "lighting/spectra.glsl"
#include "background/background.glsl"

layout(local_size_x = 16, local_size_y = 16) in;

// This pipeline's mode: where its tile list starts, and its colour in --visualize spectra.
layout(constant_id = SPECTRUM_MODE_CONSTANT_ID) const uint kSpectrumMode = 0u;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint visibilitySlot;
    uint hdrSlot;
} pc;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    LightingFrame lf = LightingFrameRef(f.lighting).l;
    SpectraFrame sf = SpectraFrameRef(lf.spectra).s;
    uint tile = UintBuffer(sf.tileBins).v[kSpectrumMode * sf.binCapacity + gl_WorkGroupID.x];
    uvec2 tileXY = uvec2(tile % lf.tilesX, tile / lf.tilesX);
    ivec2 pixel = ivec2(tileXY * LIGHT_TILE_SIZE + gl_LocalInvocationID.xy);
    if (any(greaterThanEqual(pixel, ivec2(f.viewportSize)))) return;
    vec4 color = vec4(0.0);
    uvec2 vis = loadVisibility(pc.visibilitySlot, pixel);
    if (vis.x != VISIBILITY_NONE) {
        GpuInstance inst = InstanceBuffer(f.instances).i[vis.x];
        GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
        VisTriangle tri = loadVisTriangle(f, inst, vis.y);
        VisBary bary = visBaryWithDerivatives(f, tri, pixel);
        WorldVertex a = fetchWorldVertex(f, inst, tri.v0);
        WorldVertex b = fetchWorldVertex(f, inst, tri.v1);
        WorldVertex c = fetchWorldVertex(f, inst, tri.v2);
        vec3 w = bary.center;
        SurfaceInput s;
        s.position = visInterpolate(w, a.position, b.position, c.position);
        s.normal = normalize(visInterpolate(w, a.normal, b.normal, c.normal));
        s.tangent = visInterpolate(w, a.tangent, b.tangent, c.tangent);
        s.uv = visInterpolate(w, a.uv0, b.uv0, c.uv0);
        s.uvDx = visInterpolate(bary.dx, a.uv0, b.uv0, c.uv0);
        s.uvDy = visInterpolate(bary.dy, a.uv0, b.uv0, c.uv0);
        s.uv1 = visInterpolate(w, a.uv1, b.uv1, c.uv1);
        s.uv1Dx = visInterpolate(bary.dx, a.uv1, b.uv1, c.uv1);
        s.uv1Dy = visInterpolate(bary.dy, a.uv1, b.uv1, c.uv1);
        s.frontFacing = tri.frontFacing;
        useTileDecalList(f, vec2(pixel) + 0.5); // decals (render/decals)
        MaterialSample m = evaluateMaterial(mat, s);
        useTileLightList(f, vec2(pixel) + 0.5);
        vec3 shaded = visualizeLighting(f, shadeSurface(f, m, s.position, s.normal));
        if (f.visualize == VISUALIZE_SPECTRA) {
            float l = dot(shaded, vec3(0.2126, 0.7152, 0.0722));
            shaded = mix(vec3(l / (1.0 + l)), spectrumColor(kSpectrumMode), 0.6);
        }
        color = vec4(shaded, 1.0);
    } else {
        color.rgb = backgroundAt(f, vec2(pixel) + 0.5);
        if (f.visualize == VISUALIZE_SPECTRA)
            color.rgb = mix(color.rgb, spectrumColor(kSpectrumMode), 0.3);
    }
    imageStore(gImagesRgba16f[pc.hdrSlot], pixel, color);
}
