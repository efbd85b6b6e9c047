#version 460
// Vertex shader of the depth prepass, the shadow pass and forward shading.
#include "common/vertex.glsl"

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint shadowView;
} pc;

layout(location = 0) out vec3 outPosition;
layout(location = 1) out vec3 outNormal;
layout(location = 2) out vec4 outTangent;
layout(location = 3) out vec2 outUv;
layout(location = 4) flat out uint outInstance;
layout(location = 5) out vec2 outShadelUv; // object's shadel space (decoupled path only)

invariant gl_Position; // every raster pass must produce the prepass's depth exactly

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    uint instanceId = gl_InstanceIndex;
    SHADEL_ASSERT(f, instanceId < f.instanceCount, ASSERT_INSTANCE_RANGE, instanceId, f.instanceCount);
    GpuInstance inst = InstanceBuffer(f.instances).i[instanceId];
    WorldVertex v = fetchWorldVertex(f, inst, gl_VertexIndex);
    outPosition = v.position;
    outNormal = v.normal;
    outTangent = v.tangent;
    outUv = v.uv0;
    outInstance = instanceId;
    outShadelUv = f.shadel != 0ul ? Vec2Buffer(ShadelFrameRef(f.shadel).s.shadelUvs).v[gl_VertexIndex] : vec2(0.0);
    gl_Position = (pc.shadowView != 0u ? f.sunViewProj : f.viewProj) * vec4(v.position, 1.0);
}
