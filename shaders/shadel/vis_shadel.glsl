// The shadel sample of a visibility-buffer pixel, shared by the compute marking and the compute
// resolve so both rebuild exactly the same shadel UV and derivatives (hence the same MIPs and
// chunks) from the same inputs.
#ifndef SHADEL_VIS_SHADEL_GLSL
#define SHADEL_VIS_SHADEL_GLSL
#include "common/visibility.glsl"
#include "shadel/shadel.glsl"

struct VisShadel {
    VisTriangle tri;
    VisBary bary;
    vec2 shadelUv; // the object's shadel space at the pixel centre
    vec2 texelDx;  // screen derivatives of shadelUv * mip0Size (fine, as dFdx/dFdy)
    vec2 texelDy;
};

VisShadel visShadelSample(FrameConstants f, ShadelFrame s, GpuInstance inst, GpuShadelObject o,
                          uint primitive, ivec2 pixel) {
    VisShadel v;
    v.tri = loadVisTriangle(f, inst, primitive);
    v.bary = visBaryWithDerivatives(f, v.tri, pixel);
    Vec2Buffer uvs = Vec2Buffer(s.shadelUvs);
    vec2 u0 = uvs.v[v.tri.v0], u1 = uvs.v[v.tri.v1], u2 = uvs.v[v.tri.v2];
    vec2 size = vec2(o.mip0Size);
    v.shadelUv = visInterpolate(v.bary.center, u0, u1, u2);
    precise vec2 dx = visInterpolate(v.bary.dx, u0, u1, u2) * size;
    precise vec2 dy = visInterpolate(v.bary.dy, u0, u1, u2) * size;
    v.texelDx = dx;
    v.texelDy = dy;
    return v;
}
#endif
