#version 460
// Vertex shader of the depth prepass, the shadow pass, forward shading and the visibility
// prepass.
#include "common/vertex.glsl"

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint shadowView;
} pc;

layout(location = 0) out vec3 outPosition;
layout(location = 1) out vec3 outNormal;
layout(location = 2) out vec4 outTangent;
layout(location = 3) out vec2 outUv;
layout(location = 7) out vec2 outUv1; // the second UV set (TEXCOORD_1)
layout(location = 4) flat out uint outInstance;
layout(location = 5) out vec2 outShadelUv; // object's shadel space (decoupled path only)
layout(location = 6) flat out uint outTriangle; // with visibility vertices, else 0

// Visibility vertices (scene/visibility_vertices.h): each names the scene vertex it stands for
// and, as a triangle's provoking vertex, the triangle (VISIBILITY_VERTICES_*).
layout(constant_id = VISIBILITY_VERTICES_CONSTANT_ID) const uint kVisibilityVertices =
    VISIBILITY_VERTICES_OFF;
layout(buffer_reference, scalar) readonly buffer VisibilityVertexBuffer { uvec2 v[]; };

invariant gl_Position; // every raster pass must produce the prepass's depth exactly

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    uint instanceId = gl_InstanceIndex;
    SHADEL_ASSERT(f, instanceId < f.instanceCount, ASSERT_INSTANCE_RANGE, instanceId, f.instanceCount);
    GpuInstance inst = InstanceBuffer(f.instances).i[instanceId];
    uint vertexIndex = gl_VertexIndex;
    outTriangle = 0u;
    if (kVisibilityVertices != VISIBILITY_VERTICES_OFF) {
        uvec2 visibilityVertex = VisibilityVertexBuffer(f.visibilityVertices).v[gl_VertexIndex];
        vertexIndex = visibilityVertex.x;
        outTriangle = visibilityVertex.y;
    }
    WorldVertex v = fetchWorldVertex(f, inst, vertexIndex);
    outPosition = v.position;
    outNormal = v.normal;
    outTangent = v.tangent;
    outUv = v.uv0;
    outUv1 = v.uv1;
    outInstance = instanceId;
    outShadelUv = f.shadel != 0ul ? Vec2Buffer(ShadelFrameRef(f.shadel).s.shadelUvs).v[vertexIndex] : vec2(0.0);
    if (kVisibilityVertices == VISIBILITY_VERTICES_PREPASS) { // it reads only the IDs and UVs
        outPosition = vec3(0.0);
        outNormal = vec3(0.0);
        outTangent = vec4(0.0);
        outShadelUv = vec2(0.0);
    }
    gl_Position = (pc.shadowView != 0u ? f.sunViewProj : f.viewProj) * vec4(v.position, 1.0);
}
