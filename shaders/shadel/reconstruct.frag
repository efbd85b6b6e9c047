#version 460
// Raster reconstruction (--marking raster): the decoupled objects drawn again, reading their
// shaded samples (shadel/resolve.glsl); misses and overflow fall back to forward shading.
#include "shadel/resolve.glsl"
#include "common/lighting.glsl"
#include "debug/inspect_shadel.glsl"

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
layout(location = 5) in vec2 inShadelUv;
// --inspect: the triangle, from visibility vertices (VISIBILITY_VERTICES_ALL); reading
// gl_PrimitiveID, even only there, cost lavapipe's forward shading of builtin:many a fifth.
layout(location = 6) flat in uint inTriangle;

layout(location = 0) out vec4 outColor;

vec3 forwardShade(FrameConstants f) {
    GpuInstance inst = InstanceBuffer(f.instances).i[inInstance];
    GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
    SurfaceInput si;
    si.position = inPosition;
    si.normal = normalize(inNormal);
    si.tangent = inTangent;
    si.uv = inUv;
    si.uvDx = dFdx(inUv);
    si.uvDy = dFdy(inUv);
    si.uv1 = inUv1;
    si.uv1Dx = dFdx(inUv1);
    si.uv1Dy = dFdy(inUv1);
    si.frontFacing = gl_FrontFacing;
    useTileDecalList(f, gl_FragCoord.xy); // decals, as forward shading applies them
    MaterialSample m = evaluateMaterial(mat, si);
    useLightListAt(f, gl_FragCoord.xy, inPosition); // the lights as forward shading culls them
    vec3 color = shadeSurface(f, m, inPosition, si.normal);
    if (inspecting(f, uvec2(gl_FragCoord.xy)))
        inspectSurface(f, inInstance, inTriangle, m, inPosition, si.normal, color);
    return color;
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    ShadelObjectRef o = shadelObject(s, inInstance);
    vec2 texel = inShadelUv * vec2(o.v.mip0Size);
    vec2 texelDx = dFdx(texel), texelDy = dFdy(texel);
    Reconstruction r = reconstructSample(s, o, inShadelUv, texelDx, texelDy, ivec2(gl_FragCoord.xy),
                                         reconstructionLayer(f, s));
    countReconstruction(s, r);
    vec3 color = r.color;
    bool inspect = inspecting(f, uvec2(gl_FragCoord.xy));
    if (inspect) {
        beginInspect(f, inInstance, inTriangle, gl_FragCoord);
        inspectShadels(f, s, o, r, inShadelUv, texelDx, texelDy);
    }
    bool shadeForward = r.missing + r.overflowed != 0u || r.forward;
    if (shadeForward || inspect) {
        vec3 forward = forwardShade(f); // also prints the surface under --inspect
        if (shadeForward) color = forward;
    }
    if (inspect) shaderPrintF3(f, PRINT_OUTPUT, color);
    outColor = vec4(visualizeReconstruction(f, o, r, color, inShadelUv, texelDx, texelDy), 1.0);
}
