// A transparent surface's fragment, shaded per pixel with the shared material + lighting code
// (the forward path; forward.frag does the same for opaque surfaces).
#ifndef SHADEL_TRANSPARENT_SHADING_GLSL
#define SHADEL_TRANSPARENT_SHADING_GLSL
#include "common/lighting.glsl"
#include "oit/wboit.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inTangent;
layout(location = 3) in vec2 inUv;
layout(location = 7) in vec2 inUv1; // the second UV set (TEXCOORD_1)
layout(location = 4) flat in uint inInstance;

TransparentFragment shadeTransparentFragment(FrameConstants f) {
    GpuInstance inst = InstanceBuffer(f.instances).i[inInstance];
    GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
    SurfaceInput s;
    s.position = inPosition;
    s.normal = normalize(inNormal);
    s.tangent = inTangent;
    s.uv = inUv;
    s.uvDx = dFdx(inUv);
    s.uvDy = dFdy(inUv);
    s.uv1 = inUv1;
    s.uv1Dx = dFdx(inUv1);
    s.uv1Dy = dFdy(inUv1);
    s.frontFacing = gl_FrontFacing;
    MaterialSample m = evaluateMaterial(mat, s);
    vec3 color = shadeSurface(f, m, inPosition, s.normal);
    return transparentFragment(color, m.alpha, mat.additiveness);
}
#endif
