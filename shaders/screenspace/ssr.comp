#version 460
// Screen-space reflections: the reflected ray is marched in screen space (pixels, reversed-Z
// depth, which is affine along the projected line) through the closest-depth pyramid: a cell
// whose nearest depth is behind the ray is crossed whole, and the march climbs a level; one that
// may hold the ray's hit is descended into, down to a pixel, where a hit is accepted within a
// thickness. Rays that leave the screen or hit nothing see the sky (the environment), and so do
// rougher surfaces progressively (SSR_ROUGHNESS_FADE .. SSR_MAX_ROUGHNESS). Output: reflected
// radiance and the weight the composite gives it. Permutation 1 (tiles with no smooth surface)
// only clears the target.
#include "screenspace/screen_space.glsl"
#include "environment/environment.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(constant_id = 0) const uint CLEAR_ONLY = 0u;

const int MAX_STEPS = 80;

float pyramidDepth(int level, vec2 cell) {
    return uintBitsToFloat(imageLoad(gImagesR32ui[pc.pyramid[level]], ivec2(cell)).r);
}

// Screen position (pixels, depth) of a world point; w for the near-plane test.
vec4 toScreen(FrameConstants f, vec3 world) {
    vec4 c = f.viewProj * vec4(world, 1.0);
    return vec4((c.xy / c.w * 0.5 + 0.5) * f.viewportSize, c.z / c.w, c.w);
}

// Parameter just past the boundary of the current cell the ray leaves by.
float cellExit(vec3 s0, vec3 d, vec2 pos, float cellSize) {
    vec2 cell = floor(pos / cellSize);
    vec2 boundary = (cell + step(vec2(0.0), d.xy)) * cellSize;
    vec2 tb = vec2(abs(d.x) > 1e-6 ? (boundary.x - s0.x) / d.x : 1e30,
                   abs(d.y) > 1e-6 ? (boundary.y - s0.y) / d.y : 1e30);
    return tb.x < tb.y ? tb.x + 0.02 / abs(d.x) : tb.y + 0.02 / abs(d.y);
}

// Returns (radiance of the hit pixel, how far it is from the screen's edge: hits near it fade
// to the environment, so reflections do not pop at the edge), or 0 for a miss.
vec4 march(FrameConstants f, vec3 position, vec3 dir, float viewDistance) {
    float reach = viewDistance * 1.5 + 20.0;
    vec4 a = toScreen(f, position);
    vec3 end = position + dir * reach;
    vec4 b = toScreen(f, end);
    const float nearW = 0.02;
    if (b.w < nearW) { // the ray passes the camera plane: stop just before it
        float t = (a.w - nearW) / max(a.w - b.w, 1e-6);
        b = toScreen(f, position + dir * reach * t);
    }
    vec3 s0 = a.xyz, d = b.xyz - a.xyz;
    if (length(d.xy) < 1.0) return vec4(0.0);
    float tMax = 1.0;
    vec2 size = f.viewportSize;
    if (d.x > 0.0) tMax = min(tMax, (size.x - 0.01 - s0.x) / d.x);
    if (d.x < 0.0) tMax = min(tMax, (0.01 - s0.x) / d.x);
    if (d.y > 0.0) tMax = min(tMax, (size.y - 0.01 - s0.y) / d.y);
    if (d.y < 0.0) tMax = min(tMax, (0.01 - s0.y) / d.y);

    float t = cellExit(s0, d, s0.xy, 1.0); // leave the pixel the ray starts on
    int level = 0;
    for (int i = 0; i < MAX_STEPS && t < tMax; ++i) {
        vec3 pos = s0 + d * t;
        float cellSize = float(1 << level);
        float tNext = min(cellExit(s0, d, pos.xy, cellSize), tMax);
        float closest = pyramidDepth(level, floor(pos.xy / cellSize));
        float zIn = pos.z, zOut = s0.z + d.z * tNext;
        if (min(zIn, zOut) > closest) { // in front of everything in the cell
            t = tNext;
            level = min(level + 1, int(DEPTH_PYRAMID_LEVELS) - 1);
            continue;
        }
        if (level > 0) {
            if (zIn > closest && abs(d.z) > 1e-12) t = max(t, (closest - s0.z) / d.z);
            --level;
            continue;
        }
        // A pixel whose surface the ray reaches: a hit if the ray is not far behind it.
        float behind = linearDepth(f, min(zIn, zOut)) - linearDepth(f, closest);
        float thickness = 0.1 + 0.03 * linearDepth(f, closest);
        if (behind <= thickness) {
            ivec2 hit = ivec2(floor(pos.xy));
            vec2 uv = pos.xy / size;
            vec2 edge = min(uv, 1.0 - uv);
            float keep = smoothstep(0.0, 0.08, min(edge.x, edge.y));
            return vec4(imageLoad(gImagesRgba16f[pc.hdrSlot], hit).rgb, keep);
        }
        t = tNext; // passed behind a thin surface
    }
    return vec4(0.0);
}

void main() {
    uvec2 tile = currentTile(pc.tiles, pc.listOffset);
    ivec2 p = ivec2(tile * TILE_SIZE + gl_LocalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) return;
    vec4 result = vec4(0.0);
    if (CLEAR_ONLY == 0u) {
        GBufferSample g = readGBuffer(p);
        if ((g.flags & PIXEL_SMOOTH) != 0u) {
            FrameConstants f = FrameConstantsRef(pc.frame).f;
            float depth = sceneDepthAt(p);
            vec3 position = worldPositionAt(f, vec2(p) + 0.5, depth);
            vec3 view = normalize(position - f.cameraPosition);
            vec3 dir = reflect(view, g.normal);
            // The shading already reflects the environment: the pass stores what a hit changes.
            vec3 environment = environmentSpecular(f.environment, dir, g.roughness);
            float roughFade = smoothstep(SSR_ROUGHNESS_FADE, SSR_MAX_ROUGHNESS, g.roughness);
            vec3 radiance = environment;
            if (roughFade < 1.0) {
                vec4 hit = march(f, position, dir, linearDepth(f, depth));
                radiance = mix(environment, hit.rgb, hit.w * (1.0 - roughFade));
            }
            result = vec4(radiance - environment, 1.0 - roughFade);
        }
    }
    imageStore(gImagesRgba16f[pc.ssrSlot], p, result);
}
