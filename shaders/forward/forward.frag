#version 460
// Forward shading: the shared material + lighting code evaluated per pixel.
#include "common/lighting.glsl"
#define LIGHT_CULL_FRAGMENT // helper invocations write nothing (light_cull.glsl)
#include "lighting/light_cull.glsl" // useSubgroupLightList
#include "lighting/light_debug.glsl"
#include "debug/inspect.glsl"
#include "raytracing/rt_apply.glsl"
#include "common/tone_curve.glsl"

// The prepass laid the depth down and this pass tests against it (equal) without writing it, so
// the test can run before shading. Declared because this shader has side effects (the texture
// streaming feedback's atomics, --inspect prints): without it lavapipe tests depth after shading
// and shades every occluded fragment too (builtin:default 1280x720: 390 -> 200 ms).
layout(early_fragment_tests) in;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint shadowView;
} pc;

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inTangent;
layout(location = 3) in vec2 inUv;
layout(location = 7) in vec2 inUv1; // the second UV set (TEXCOORD_1)
layout(location = 4) flat in uint inInstance;
// --inspect: the triangle, from visibility vertices (VISIBILITY_VERTICES_ALL); reading
// gl_PrimitiveID, even only there, cost lavapipe's forward shading of builtin:many a fifth.
layout(location = 6) flat in uint inTriangle;

layout(location = 0) out vec4 outColor;

// The frame's tonemap fused into this pass (render/post/tonemap.h): display colour into an RGBA8
// target, alpha 1 (coverage; the target clears to the sky's display colour with alpha 0).
layout(constant_id = FORWARD_DISPLAY_OUTPUT_CONSTANT_ID) const bool kDisplayOutput = false;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    GpuInstance inst = InstanceBuffer(f.instances).i[inInstance];
    GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
    gTextureFeedback = f.textureFeedback; // texture streaming: the MIPs shading wants
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
    // Decals land on opaque surfaces: the list of this pixel's tile (render/decals).
    if ((mat.flags & MATERIAL_ALPHA_BLEND) == 0u) useTileDecalList(f, gl_FragCoord.xy);
    MaterialSample m = evaluateMaterial(mat, s);
    if ((mat.flags & MATERIAL_ALPHA_MASK) != 0u && m.alpha < mat.alphaCutoff) discard;
    // Opaque pixels lie on the prepass depth the tile's bounds came from; blended ones need not.
    if ((mat.flags & MATERIAL_ALPHA_BLEND) == 0u) {
        useLightListAt(f, gl_FragCoord.xy, inPosition);
        useSubgroupLightList(f, true, inPosition); // only with few lights (LightingFrame)
        useRayTracedPixelTerms(f, gl_FragCoord.xy); // --rt-*: this pixel's traced terms
    }
    vec3 color = shadeSurface(f, m, inPosition, s.normal);
    if (inspecting(f, uvec2(gl_FragCoord.xy))) {
        beginInspect(f, inInstance, inTriangle, gl_FragCoord);
        bool uv1 = materialReadsUv1(mat, TEXTURE_SLOT_BASE_COLOR);
        vec2 footprint = max(abs(uv1 ? s.uv1Dx : s.uvDx), abs(uv1 ? s.uv1Dy : s.uvDy));
        if (mat.baseColorTexture != NO_TEXTURE)
            footprint *= vec2(textureSize(gTextures[nonuniformEXT(mat.baseColorTexture)], 0));
        shaderPrintF(f, PRINT_UV_LOD, log2(max(max(footprint.x, footprint.y), 1e-8)));
        inspectSurface(f, inInstance, inTriangle, m, inPosition, s.normal, color);
    }
    color = visualizeLighting(f, color);
    float alpha = (mat.flags & MATERIAL_ALPHA_BLEND) != 0u ? m.alpha : 1.0;
    outColor = kDisplayOutput ? vec4(displayColor(color, f.exposure, f.tonemap), 1.0) : vec4(color, alpha);
}
