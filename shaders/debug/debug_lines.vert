#version 460
// Debug lines: vertex pulling from the line buffer, two vertices per segment.
#include "debug/debug_lines.glsl"

layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;
layout(location = 0) out vec3 outColor;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    GpuDebugLine line = DebugLinesRef(f.debugLines).lines[gl_VertexIndex >> 1];
    bool second = (gl_VertexIndex & 1) != 0;
    gl_Position = f.viewProj * vec4(second ? line.b : line.a, 1.0);
    outColor = unpackUnorm4x8(second ? line.colorB : line.colorA).rgb;
}
