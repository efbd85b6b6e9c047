#version 460
// Visibility prepass (--marking visibility): depth plus, per pixel, the instance and the
// triangle that won the depth test (numbered within its mesh), carried by its provoking vertex
// (scene/visibility_vertices.h; reading gl_PrimitiveID cost lavapipe's prepass a fifth of its
// time). Alpha-masked materials discard as in the depth prepass.
#include "common/material.glsl"

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint shadowView;
} pc;

layout(location = 3) in vec2 inUv;
layout(location = 7) in vec2 inUv1; // the second UV set (TEXCOORD_1)
layout(location = 4) flat in uint inInstance;
layout(location = 6) flat in uint inTriangle; // from the provoking vertex (kVisibilityVertices)

layout(location = 0) out uvec2 outVisibility;

layout(constant_id = ALPHA_MASK_CONSTANT_ID) const bool kAlphaMasked = true;

void main() {
    if (kAlphaMasked) { // compiled out for scenes without alpha-masked materials: early Z
        FrameConstants f = FrameConstantsRef(pc.frame).f;
        GpuInstance inst = InstanceBuffer(f.instances).i[inInstance];
        GpuMaterial m = MaterialBuffer(f.materials).m[inst.material];
        if ((m.flags & MATERIAL_ALPHA_MASK) != 0u) {
            vec2 uv = materialSlotUv(m, TEXTURE_SLOT_BASE_COLOR, inUv, inUv1);
            if (materialBaseAlpha(m, uv, dFdx(uv), dFdy(uv)) < m.alphaCutoff) discard;
        }
    }
    outVisibility = uvec2(inInstance, inTriangle);
}
