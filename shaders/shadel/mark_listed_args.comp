#version 460
// Indirect arguments of marking's second pass from the quads its first pass listed: 64 per
// group, 2-D past 65535 groups (common/dispatch_2d.h).
#include "shadel/mark_quad.glsl"
#include "common/dispatch_2d.h"

layout(local_size_x = 1) in;

void main() {
    MarkQuadList list = MarkQuadList(pc.markList);
    uint groups = (list.count + 63u) / 64u;
    list.dispatch = uvec4(dispatch2d(groups), 1u, list.count);
}
