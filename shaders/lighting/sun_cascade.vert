#version 460
// The sun's cascaded shadow maps (render/lighting/sun_cascades.h): the scene's depth from the
// sun into cascade `shadowView`'s rectangle of the atlas (the viewport). The push block is the
// forward passes' (forward/depth.frag is the fragment stage: alpha-masked cut-outs).
#include "common/vertex.glsl"

layout(buffer_reference, scalar) readonly buffer LightingFrameRef { LightingFrame l; };
layout(buffer_reference, scalar) readonly buffer SunCascadesRef { GpuSunCascades c; };

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint shadowView;
} pc;

layout(location = 3) out vec2 outUv;
layout(location = 7) out vec2 outUv1; // the second UV set (TEXCOORD_1)
layout(location = 4) flat out uint outInstance;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    uint instanceId = gl_InstanceIndex;
    GpuInstance inst = InstanceBuffer(f.instances).i[instanceId];
    WorldVertex v = fetchWorldVertex(f, inst, gl_VertexIndex);
    outUv = v.uv0;
    outUv1 = v.uv1;
    outInstance = instanceId;
    LightingFrame lf = LightingFrameRef(f.lighting).l;
    gl_Position = SunCascadesRef(lf.sunCascades).c.viewProj[pc.shadowView] * vec4(v.position, 1.0);
}
