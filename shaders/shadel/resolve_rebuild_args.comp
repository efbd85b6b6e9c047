#version 460
// Indirect arguments of the resolve's rebuild pass from the pixels the resolve listed: 64 per
// group, 2-D past 32768 groups (every device's maxComputeWorkGroupCount[0] allows 65535).
#include "shadel/resolve_pixel.glsl"

layout(local_size_x = 1) in;

void main() {
    ResolveRebuildList list = ResolveRebuildList(pc.rebuildList);
    uint groups = (list.count + 63u) / 64u;
    list.dispatch = uvec4(min(groups, 32768u), max((groups + 32767u) / 32768u, 1u), 1u, list.count);
}
