#version 460
// Decoupled transparency (--mode decoupled, --oit wboit): transparent surfaces drawn again,
// their lit colour reconstructed from shadel space like opaque ones (shadel/resolve.glsl; a
// miss falls back to forward shading), their coverage evaluated per pixel (one texture fetch,
// so sprite edges stay sharp), and the fragment accumulated into the WBOIT targets.
#include "shadel/resolve.glsl"
#include "oit/transparent_shading.glsl"

layout(early_fragment_tests) in;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint shadowView;
} pc;

layout(location = 5) in vec2 inShadelUv;

layout(location = 0) out vec4 outAccum;
layout(location = 1) out vec4 outReveal;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    ShadelObjectRef o = shadelObject(s, inInstance);
    vec2 texel = inShadelUv * vec2(o.v.mip0Size);
    vec2 texelDx = dFdx(texel), texelDy = dFdy(texel);
    Reconstruction r = reconstructSample(s, o, inShadelUv, texelDx, texelDy, ivec2(gl_FragCoord.xy),
                                         reconstructionLayer(f, s));
    countReconstruction(s, r);
    GpuMaterial mat = MaterialBuffer(f.materials).m[InstanceBuffer(f.instances).i[inInstance].material];
    vec2 uv = materialSlotUv(mat, TEXTURE_SLOT_BASE_COLOR, inUv, inUv1);
    vec2 uvDx = dFdx(uv), uvDy = dFdy(uv); // outside any branch
    float alpha = materialBaseAlpha(mat, uv, uvDx, uvDy);
    TransparentFragment t = transparentFragment(r.color, alpha, mat.additiveness);
    if (r.missing + r.overflowed != 0u) t = shadeTransparentFragment(f);
    t.premultiplied = visualizeReconstruction(f, o, r, t.premultiplied, inShadelUv, texelDx, texelDy);
    wboitOutputs(t, viewDepthOf(f, inPosition), outAccum, outReveal);
}
