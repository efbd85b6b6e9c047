// The world-space volume of a 16x16-pixel screen tile between its depth bounds, as the tiled
// culling passes test it (lights: lighting/tile_cull.comp; decals: decals/tile_cull.comp), and
// which pixels each of a tile's TILE_CULL_THREADS invocations reads for its depth bounds.
#ifndef COMMON_TILE_FRUSTUM_GLSL
#define COMMON_TILE_FRUSTUM_GLSL
#include "common/bindless.glsl" // FrameConstants, LIGHT_TILE_SIZE

// 64 invocations per tile, not one per pixel: everything a tile does but read its pixels (its
// frustum, the light grid's query, the barriers) is the same for each invocation or each
// subgroup, and where a workgroup's subgroups run in turn (lavapipe: 8 lanes each) it was paid
// 32 times per tile. Measured on builtin:lights 1280x720 (forward, spectra on, lavapipe): light
// culling 81-116 ms with 256 invocations, 37-54 with 64, 31-32 with 32; 64 keeps a whole
// subgroup or two per tile on GPUs (32 or 64 lanes) and the candidate loops a few rounds deep.
#define TILE_CULL_SIDE 8 // invocations per side of the workgroup: half the tile's
#define TILE_CULL_THREADS uint(TILE_CULL_SIDE * TILE_CULL_SIDE)

// The q-th (0..3) pixel this invocation reads: its place in each of the tile's four quarters,
// so neighbouring invocations read neighbouring pixels.
ivec2 tileCullPixel(uint q) {
    return ivec2(gl_WorkGroupID.xy * LIGHT_TILE_SIZE + gl_LocalInvocationID.xy) +
           ivec2(q & 1u, q >> 1u) * TILE_CULL_SIDE;
}

// Reversed Z: depth 0 is the sky. Folds one pixel's depth into the running bounds (the bits of
// positive floats order as the floats do).
void tileDepthBoundsAdd(float depth, inout uint depthMin, inout uint depthMax) {
    if (depth <= 0.0) return;
    depthMin = min(depthMin, floatBitsToUint(depth));
    depthMax = max(depthMax, floatBitsToUint(depth));
}

struct TileFrustum {
    vec3 corners[8]; // near (i & 4 == 0) and far corners, x by bit 0 and y by bit 1
    vec4 planes[6];  // facing inward: four sides through the eye, near and far
    vec3 boxMin, boxMax;
    vec3 centre;  // of the corners
    float radius; // of the corners about the centre (a bounding sphere, for spot cones)
};

// Tile `tile` (in tiles) between reversed-Z depths dNear >= dFar.
TileFrustum tileFrustum(FrameConstants f, uvec2 tile, float dNear, float dFar) {
    TileFrustum t;
    vec2 lo = vec2(tile * LIGHT_TILE_SIZE) * f.invViewportSize * 2.0 - 1.0;
    vec2 hi = min(vec2((tile + 1u) * LIGHT_TILE_SIZE) * f.invViewportSize, vec2(1.0)) * 2.0 - 1.0;
    for (int i = 0; i < 8; ++i) {
        vec4 clip = vec4((i & 1) != 0 ? hi.x : lo.x, (i & 2) != 0 ? hi.y : lo.y,
                         (i & 4) != 0 ? dFar : dNear, 1.0);
        vec4 w = f.invViewProj * clip;
        t.corners[i] = w.xyz / w.w;
    }
    vec3 eye = f.cameraPosition;
    t.centre = vec3(0.0);
    for (int i = 0; i < 8; ++i) t.centre += t.corners[i] * 0.125;
    const ivec2 edges[4] = ivec2[4](ivec2(0, 1), ivec2(1, 3), ivec2(3, 2), ivec2(2, 0));
    for (int e = 0; e < 4; ++e) {
        vec3 n = normalize(cross(t.corners[edges[e].x + 4] - eye, t.corners[edges[e].y + 4] - eye));
        if (dot(n, t.centre - eye) < 0.0) n = -n;
        t.planes[e] = vec4(n, -dot(n, eye));
    }
    vec3 forward = normalize(-vec3(f.view[0][2], f.view[1][2], f.view[2][2]));
    float zMin = 1e30, zMax = -1e30;
    for (int i = 0; i < 8; ++i) {
        float z = dot(t.corners[i] - eye, forward);
        zMin = min(zMin, z), zMax = max(zMax, z);
    }
    t.planes[4] = vec4(forward, -dot(forward, eye) - zMin);
    t.planes[5] = vec4(-forward, dot(forward, eye) + zMax);
    t.boxMin = t.corners[0], t.boxMax = t.corners[0];
    for (int i = 1; i < 8; ++i) t.boxMin = min(t.boxMin, t.corners[i]), t.boxMax = max(t.boxMax, t.corners[i]);
    t.radius = 0.0;
    for (int i = 0; i < 8; ++i) t.radius = max(t.radius, distance(t.corners[i], t.centre));
    return t;
}
#endif
