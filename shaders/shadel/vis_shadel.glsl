// The shadel samples of visibility-buffer pixels, shared by the compute marking and the compute
// resolve so both rebuild exactly the same shadel UV and derivatives (hence the same MIPs and
// chunks) from the same inputs. One invocation handles a 2x2 quad of pixels (aligned as the
// rasterizer's quads): pixels of the same triangle share its setup and the four barycentrics,
// and its derivatives are the quad's coarse ones (dFdxCoarse/dFdyCoarse: the differences along
// the quad's first row and column, as GPUs take a quad's texture LOD), so the quad's pixels of
// one triangle share their MIP choice and marking takes it once (mark_visibility.comp).
#ifndef SHADEL_VIS_SHADEL_GLSL
#define SHADEL_VIS_SHADEL_GLSL
#include "common/visibility.glsl"
#include "shadel/shadel.glsl"

struct VisQuad {
    VisTriangle tri;
    vec3 bary[4]; // at the quad's pixel centres: (0,0) (1,0) (0,1) (1,1)
    vec2 uv0, uv1, uv2; // shadel UVs of the triangle's vertices
};

void visQuadSetup(FrameConstants f, ShadelFrame s, GpuInstance inst, uint triangle,
                  ivec2 quadOrigin, out VisQuad q) {
    q.tri = loadVisTriangle(f, inst, triangle);
    for (int i = 0; i < 4; ++i)
        q.bary[i] = visBarycentrics(q.tri, pixelNdc(f, quadOrigin + ivec2(i & 1, i >> 1)));
    Vec2Buffer uvs = Vec2Buffer(s.shadelUvs);
    q.uv0 = uvs.v[q.tri.v0];
    q.uv1 = uvs.v[q.tri.v1];
    q.uv2 = uvs.v[q.tri.v2];
}

struct VisShadel {
    VisBary bary;
    vec2 shadelUv; // the object's shadel space at the pixel centre
    vec2 texelDx;  // screen derivatives of shadelUv * mip0Size (fine, as dFdx/dFdy)
    vec2 texelDy;
};

// Pixel `i` of the quad (x = i & 1, y = i >> 1).
VisShadel visShadelSample(VisQuad q, ShadelObjectRef o, int i) {
    VisShadel v;
    v.bary.center = q.bary[i];
    precise vec3 bdx = q.bary[1] - q.bary[0];
    precise vec3 bdy = q.bary[2] - q.bary[0];
    v.bary.dx = bdx;
    v.bary.dy = bdy;
    vec2 size = vec2(o.v.mip0Size);
    v.shadelUv = visInterpolate(v.bary.center, q.uv0, q.uv1, q.uv2);
    precise vec2 dx = visInterpolate(bdx, q.uv0, q.uv1, q.uv2) * size;
    precise vec2 dy = visInterpolate(bdy, q.uv0, q.uv1, q.uv2) * size;
    v.texelDx = dx;
    v.texelDy = dy;
    return v;
}
#endif
