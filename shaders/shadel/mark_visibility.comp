#version 460
// Compute marking (--marking visibility), first pass: one invocation per 2x2 quad of the
// visibility buffer. Pixels of decoupled instances rebuild their shadel UV and its screen
// derivatives from the triangle and the pixel ray (shadel/vis_shadel.glsl), mark what the
// resolve will read and write it down for the resolve (shadel/resolve_address.glsl).
//
// A quad whose four pixels see one decoupled triangle (85% of builtin:default's covered quads
// at 1280x720) is marked here, without per-pixel branches (markQuadOnTriangles); sky and forward
// (hybrid) quads get addresses saying so. The others are listed: those whose four pixels see two
// triangles of one decoupled instance for mark_two_triangles.comp, every other one (silhouettes,
// sky edges, the screen's last row or column, rare level-window fallbacks) for mark_listed.comp,
// which marks it pixel by pixel (markQuadPixel). See shadel/mark_quad.glsl for why.
//
// The quad's derivatives are coarse (shadel/vis_shadel.glsl), so its pixels of one triangle
// share their MIP levels and anisotropy, taken once with the setup (setUpQuad).
#include "shadel/mark_quad.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

void main() {
    ivec2 origin = ivec2(gl_GlobalInvocationID.xy) * 2;
    bool twoTriangles = false, pixels = false;
    // (loaded before any branch: lavapipe loads a uniform address once only outside control flow)
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    if (origin.x < int(pc.width) && origin.y < int(pc.height)) {
        uvec2 vis[4];
        loadQuadVisibility(origin, vis);
        bool whole = origin.x + 1 < int(pc.width) && origin.y + 1 < int(pc.height);
        bool oneInstance = whole && vis[1].x == vis[0].x && vis[2].x == vis[0].x &&
                           vis[3].x == vis[0].x;
        bool one = oneInstance && vis[1].y == vis[0].y && vis[2].y == vis[0].y &&
                   vis[3].y == vis[0].y;
        bool decoupled = oneInstance && vis[0].x != VISIBILITY_NONE &&
                         (shadelObject(s, vis[0].x).v.flags & SHADEL_OBJECT_DECOUPLED) != 0u;
        if (decoupled && one) {
            QuadTriangle t = setUpQuad(f, s, vis[0], origin);
            pixels = !markQuadOnTriangles(s, t, t, 0u, origin);
        } else if (one) { // the sky, or a forward (hybrid) instance: drawn before the resolve
            uint first = resolveAddressIndex(origin, pc.width);
            uvec4 address =
                vis[0].x == VISIBILITY_NONE ? resolveAddressNone() : resolveAddressForward();
            for (uint i = 0u; i < 4u; ++i)
                ResolveAddressBuffer(pc.addresses).v[first + i] = address;
        } else if (decoupled) { // two triangles of the instance, or more
            uint b = vis[1].y != vis[0].y ? vis[1].y : vis[2].y != vis[0].y ? vis[2].y : vis[3].y;
            twoTriangles = true;
            for (int i = 1; i < 4; ++i) twoTriangles = twoTriangles && (vis[i].y == vis[0].y || vis[i].y == b);
            pixels = !twoTriangles;
        } else {
            pixels = true;
        }
    }
    listMarkQuad(origin, twoTriangles, pixels); // (every invocation arrives here)
}
