#version 460
// The draw's vertex count from the segments appended this frame (at most the capacity).
#include "debug/debug_lines.glsl"

layout(local_size_x = 1) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

void main() {
    DebugLinesRef d = DebugLinesRef(FrameConstantsRef(pc.frame).f.debugLines);
    d.header.vertexCount = 2u * min(d.header.count, d.header.capacity);
}
