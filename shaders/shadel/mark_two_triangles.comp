#version 460
// Compute marking, second pass: the listed quads whose four pixels see two triangles of one
// decoupled instance (a triangle edge crosses the quad; mark_visibility.comp lists them). Both
// triangles are set up and, where their levels agree, the quad is marked without per-pixel
// branches (markQuadOnTriangles); the others are listed for the per-pixel pass
// (mark_listed.comp). Indirect dispatch (mark_listed_args.comp), 2-D past 65535 groups
// (common/dispatch_2d.h).
#include "shadel/mark_quad.glsl"
#include "common/dispatch_2d.h"

layout(local_size_x = 64) in;

void main() {
    MarkQuadList list = MarkQuadList(pc.markList);
    uint index = dispatch2dGroup() * 64u + gl_LocalInvocationIndex;
    bool listed = false;
    ivec2 origin = ivec2(0);
    // (loaded before any branch: lavapipe loads a uniform address once only outside control flow)
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    if (index < list.twoTriangleCount) {
        origin = unpackQuadOrigin(list.quads[index]);
        uvec2 vis[4];
        loadQuadVisibility(origin, vis);
        uvec2 b = vis[1] != vis[0] ? vis[1] : vis[2] != vis[0] ? vis[2] : vis[3];
        uint onB = 0u;
        for (int i = 1; i < 4; ++i) onB |= vis[i] == b ? 1u << i : 0u;
        listed = !markQuadOnTriangles(s, setUpQuad(f, s, vis[0], origin),
                                      setUpQuad(f, s, b, origin), onB, origin);
    }
    listMarkQuad(origin, false, listed); // (every invocation arrives here)
}
