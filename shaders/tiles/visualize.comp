#version 460
// --visualize tiles: each 8x8 tile tinted by its class (sky blue, SSR green, SSR clear-only
// grey, skin red, sky edge yellow border), over the image.
#include "screenspace/screen_space.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) return;
    uvec2 tile = gl_WorkGroupID.xy;
    uint tileCount = gl_NumWorkGroups.x * gl_NumWorkGroups.y;
    uint mask = TileBuffer(pc.tiles).entries[TILE_LIST_COUNT * tileCount + tile.y * pc.tilesX + tile.x];
    vec3 tint = vec3(0.0);
    if ((mask & (1u << TILE_LIST_SKY)) != 0u) tint = vec3(0.1, 0.3, 1.0);
    if ((mask & (1u << TILE_LIST_SSR)) != 0u) tint = vec3(0.1, 0.9, 0.2);
    if ((mask & (1u << TILE_LIST_SSR_CLEAR)) != 0u) tint = vec3(0.4);
    if ((mask & (1u << TILE_LIST_SSS)) != 0u) tint = vec3(1.0, 0.15, 0.1);
    bool border = any(equal(gl_LocalInvocationID.xy, uvec2(0u)));
    if (border && (mask & (1u << TILE_LIST_SKY_EDGE)) != 0u) tint = vec3(1.0, 0.9, 0.0);
    vec4 c = imageLoad(gImagesRgba16f[pc.hdrSlot], p);
    c.rgb = mix(c.rgb, tint, border ? 0.8 : 0.45);
    imageStore(gImagesRgba16f[pc.hdrSlot], p, c);
}
