#version 460
// Compute marking, second pass: the quads the first pass (mark_visibility.comp) listed, marked
// pixel by pixel (shadel/mark_quad.glsl markQuadPixels). Indirect dispatch
// (mark_listed_args.comp), 2-D past 65535 groups (common/dispatch_2d.h).
#include "shadel/mark_quad.glsl"
#include "common/dispatch_2d.h"

layout(local_size_x = 64) in;

void main() {
    MarkQuadList list = MarkQuadList(pc.markList);
    uint index = dispatch2dGroup() * 64u + gl_LocalInvocationIndex;
    if (index >= list.count) return;
    uint packed = list.quads[index];
    ivec2 origin = ivec2(packed & 0xFFFFu, packed >> 16);
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    uvec2 vis[4];
    loadQuadVisibility(origin, vis);
    markQuadPixels(f, s, origin, vis);
}
