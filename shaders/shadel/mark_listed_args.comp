#version 460
// Indirect arguments of marking's later passes from the quads listed for them: the
// two-triangle pass's (after the first pass) or the per-pixel pass's (after the second), 2-D
// past 65535 groups (common/dispatch_2d.h). The counts go to the frame's counters too (stats).
#include "shadel/mark_quad.glsl"
#include "common/dispatch_2d.h"

layout(local_size_x = 1) in;

layout(constant_id = MARK_PIXEL_LIST_CONSTANT_ID) const bool kPixelList = false;

void main() {
    MarkQuadList list = MarkQuadList(pc.markList);
    ShadelCountersRef counters = ShadelCountersRef(ShadelFrameRef(FrameConstantsRef(pc.frame).f.shadel).s.counters);
    // (the per-pixel pass runs an invocation per pixel: 16 quads per group)
    uint count = kPixelList ? list.pixelCount : list.twoTriangleCount;
    uint perGroup = kPixelList ? 16u : 64u;
    uvec4 dispatch = uvec4(dispatch2d((count + perGroup - 1u) / perGroup), 1u, count);
    if (kPixelList) {
        list.pixelDispatch = dispatch;
        counters.c.markQuadsPerPixel = count;
    } else {
        list.twoTriangleDispatch = dispatch;
        counters.c.markQuadsTwoTriangles = count;
    }
}
