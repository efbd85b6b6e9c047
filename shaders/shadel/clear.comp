#version 460
// Clears the occupancy and offset map of every block in this frame's rects. Only the rects in
// use are walked, so the cost follows what is allocated, not the size of the virtual sheet.
#include "shadel/shadel.glsl"
#include "shadel/rects.glsl"

layout(local_size_x = 64) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

void main() {
    ShadelFrame s = ShadelFrameRef(FrameConstantsRef(pc.frame).f.shadel).s;
    uint t = gl_GlobalInvocationID.x;
    if (t >= s.rectBlockCount) return;
    GpuShadelRect r;
    uint block = rectBlock(s, t, r);
    Uint64Buffer(s.occupancy).v[block] = 0ul;
    UintBuffer(s.offsetMap).v[block] = SHADEL_INVALID;
}
