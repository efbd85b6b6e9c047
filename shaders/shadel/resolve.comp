#version 460
// Compute resolve (--marking visibility): one thread per screen pixel. Decoupled pixels read
// their shadels with the same sample as the compute marking (shadel/vis_shadel.glsl) and the
// same filter as the raster reconstruction (shadel/resolve.glsl); misses and overflow are
// shaded forward here from the rebuilt attributes. Every other pixel gets the sky: forward
// (hybrid) instances are drawn over it by the raster pass that follows.
#include "shadel/resolve.glsl"
#include "shadel/vis_shadel.glsl"
#include "common/lighting.glsl"
#include "common/vertex.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint visibilitySlot;
    uint width;
    uint height;
    uint hdrSlot;
} pc;

vec3 forwardShade(FrameConstants f, GpuInstance inst, VisShadel v) {
    GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
    WorldVertex a = fetchWorldVertex(f, inst, v.tri.v0);
    WorldVertex b = fetchWorldVertex(f, inst, v.tri.v1);
    WorldVertex c = fetchWorldVertex(f, inst, v.tri.v2);
    vec3 w = v.bary.center;
    SurfaceInput si;
    si.position = visInterpolate(w, a.position, b.position, c.position);
    si.normal = normalize(visInterpolate(w, a.normal, b.normal, c.normal));
    si.tangent = visInterpolate(w, a.tangent, b.tangent, c.tangent);
    si.uv = visInterpolate(w, a.uv0, b.uv0, c.uv0);
    si.uvDx = visInterpolate(v.bary.dx, a.uv0, b.uv0, c.uv0);
    si.uvDy = visInterpolate(v.bary.dy, a.uv0, b.uv0, c.uv0);
    si.frontFacing = v.tri.frontFacing;
    MaterialSample m = evaluateMaterial(mat, si);
    return shadeSurface(f, m, si.position, si.normal);
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(pc.width) || pixel.y >= int(pc.height)) return;
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    vec4 color = vec4(f.skyColor, 0.0); // what the raster colour pass clears to
    uvec2 vis = loadVisibility(pc.visibilitySlot, pixel);
    if (vis.x != VISIBILITY_NONE) {
        ShadelFrame s = ShadelFrameRef(f.shadel).s;
        GpuShadelObject o = ShadelObjectBuffer(s.objects).o[vis.x];
        if ((o.flags & SHADEL_OBJECT_DECOUPLED) != 0u) {
            GpuInstance inst = InstanceBuffer(f.instances).i[vis.x];
            VisShadel v = visShadelSample(f, s, inst, o, vis.y, pixel);
            Reconstruction r = reconstructSample(s, o, v.shadelUv, v.texelDx, v.texelDy, pixel);
            vec3 c = r.color;
            if (r.missing + r.overflowed != 0u) c = forwardShade(f, inst, v);
            color = vec4(visualizeReconstruction(f, o, r, c, v.shadelUv, v.texelDx, v.texelDy), 1.0);
        }
    }
    imageStore(gImagesRgba16f[pc.hdrSlot], pixel, color);
}
