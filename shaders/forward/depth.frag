#version 460
// Depth prepass / shadow pass: only alpha-masked materials need a fragment shader's work. A
// scene without them draws these passes depth-only (no fragment shader: early Z).
#include "common/material.glsl"

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint shadowView;
} pc;

layout(location = 3) in vec2 inUv;
layout(location = 7) in vec2 inUv1; // the second UV set (TEXCOORD_1)
layout(location = 4) flat in uint inInstance;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    GpuInstance inst = InstanceBuffer(f.instances).i[inInstance];
    GpuMaterial m = MaterialBuffer(f.materials).m[inst.material];
    if ((m.flags & MATERIAL_ALPHA_MASK) != 0u) {
        vec2 uv = materialSlotUv(m, TEXTURE_SLOT_BASE_COLOR, inUv, inUv1);
        if (materialBaseAlpha(m, uv, dFdx(uv), dFdy(uv)) < m.alphaCutoff) discard;
    }
}
