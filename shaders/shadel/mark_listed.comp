#version 460
// Compute marking, third pass: the quads the earlier passes (mark_visibility.comp,
// mark_two_triangles.comp) listed for it, marked pixel by pixel: one invocation per pixel
// (shadel/mark_quad.glsl markQuadPixel). Indirect dispatch (mark_listed_args.comp), 2-D past
// 65535 groups (common/dispatch_2d.h).
//
// Why a pixel per invocation: these quads see up to four triangles, and each pixel sets up its
// own. With a quad per invocation the pixels' loop set up every triangle a SIMD group's quads
// saw, for all its lanes (lavapipe runs a branch's code whenever one lane takes it).
#include "shadel/mark_quad.glsl"
#include "common/dispatch_2d.h"

layout(local_size_x = 64) in;

void main() {
    MarkQuadList list = MarkQuadList(pc.markList);
    uint index = dispatch2dGroup() * 64u + gl_LocalInvocationIndex;
    uint quad = index >> 2;
    // (loaded before any branch: lavapipe loads a uniform address once only outside control flow)
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    if (quad >= list.pixelCount) return;
    ivec2 origin = unpackQuadOrigin(list.quads[markQuadCapacity() + quad]);
    int i = int(index & 3u);
    ivec2 pixel = min(origin + ivec2(i & 1, i >> 1), ivec2(pc.width, pc.height) - 1);
    markQuadPixel(f, s, origin, i, loadVisibility(pc.visibilitySlot, pixel));
}
