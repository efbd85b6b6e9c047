#version 460
// Indirect arguments of the resolve's rebuild pass from the pixels the resolve listed: 64 per
// group, 2-D past 65535 groups (common/dispatch_2d.h).
#include "shadel/resolve_pixel.glsl"
#include "common/dispatch_2d.h"

layout(local_size_x = 1) in;

void main() {
    ResolveRebuildList list = ResolveRebuildList(pc.rebuildList);
    uint groups = (list.count + 63u) / 64u;
    list.dispatch = uvec4(dispatch2d(groups), 1u, list.count);
}
