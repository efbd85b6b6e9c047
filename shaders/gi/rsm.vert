#version 460
// Reflective shadow map: the scene from a light (the sun or a shadow-casting spot).
#include "common/vertex.glsl"
#include "gi/rsm_push.glsl"

layout(location = 0) out vec3 outPosition;
layout(location = 1) out vec3 outNormal;
layout(location = 2) out vec4 outTangent;
layout(location = 3) out vec2 outUv;
layout(location = 7) out vec2 outUv1; // the second UV set (TEXCOORD_1)
layout(location = 4) flat out uint outInstance;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    GpuInstance inst = InstanceBuffer(f.instances).i[gl_InstanceIndex];
    WorldVertex v = fetchWorldVertex(f, inst, gl_VertexIndex);
    outPosition = v.position;
    outNormal = v.normal;
    outTangent = v.tangent;
    outUv = v.uv0;
    outUv1 = v.uv1;
    outInstance = gl_InstanceIndex;
    gl_Position = pc.viewProj * vec4(v.position, 1.0);
}
