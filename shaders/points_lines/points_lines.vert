#version 460
// glTF points and lines (render/points_lines): world positions pulled from their own buffer.
#include "common/bindless.glsl"

struct PointLineVertex {
    vec3 position;
    vec4 color;
};
layout(buffer_reference, scalar) readonly buffer PointLineVertices { PointLineVertex v[]; };

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t vertices;
} pc;
layout(location = 0) out vec4 outColor;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    PointLineVertex v = PointLineVertices(pc.vertices).v[gl_VertexIndex];
    gl_Position = f.viewProj * vec4(v.position, 1.0);
    gl_PointSize = 1.0; // one internal pixel: larger points would need the largePoints feature
    outColor = v.color;
}
