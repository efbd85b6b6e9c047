#version 460
// The thin G-buffer: what the screen-space passes read of the visible surface, drawn
// with the prepass depth (equal test): world normal + roughness, and a byte of PIXEL_* flags
// with the surface class. Sky pixels keep the cleared 0.
#include "common/material.glsl"
#include "tiles/tile_types.h"
#include "screenspace/screen_space_types.h"

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

layout(location = 0) out vec4 outNormalRoughness;
layout(location = 1) out float outFlags;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
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
    if ((mat.flags & MATERIAL_ALPHA_MASK) != 0u && m.alpha < mat.alphaCutoff) discard;
    uint surfaceClass = (mat.flags >> MATERIAL_CLASS_SHIFT) & MATERIAL_CLASS_MASK;
    if (m.unlit) surfaceClass = 4u; // SurfaceClass::Unlit
    uint flags = PIXEL_SURFACE;
    if (!m.unlit && m.roughness < SSR_MAX_ROUGHNESS) flags |= PIXEL_SMOOTH;
    if (surfaceClass == 2u) flags |= PIXEL_SKIN;
    if (surfaceClass == 3u) flags |= PIXEL_WATER;
    outNormalRoughness = vec4(m.normal, m.roughness); // double-sided: flipped by the material
    outFlags = float(flags | (surfaceClass << PIXEL_CLASS_SHIFT)) / 255.0;
}
