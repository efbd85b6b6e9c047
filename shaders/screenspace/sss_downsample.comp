#version 460
// Subsurface scattering, step 1: skin lighting at half resolution. A half-resolution texel is
// skin when any of its 2x2 pixels is; it keeps their mean colour and linear depth (alpha 0:
// not skin). One 4x4 workgroup per 8x8-pixel tile.
#include "screenspace/sss.glsl"

layout(local_size_x = 4, local_size_y = 4) in;

void main() {
    uvec2 tile = currentTile(pc.tiles, pc.listOffset);
    ivec2 h = ivec2(tile * (TILE_SIZE / 2u) + gl_LocalInvocationID.xy);
    if (h.x >= int(halfSize().x) || h.y >= int(halfSize().y)) return;
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    vec3 color = vec3(0.0);
    float depth = 0.0, n = 0.0;
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 2; ++x) {
            ivec2 p = h * 2 + ivec2(x, y);
            if (p.x >= int(pc.width) || p.y >= int(pc.height)) continue;
            if ((pixelFlagsAt(p) & PIXEL_SKIN) == 0u) continue;
            color += imageLoad(gImagesRgba16f[pc.hdrSlot], p).rgb;
            depth += linearDepth(f, sceneDepthAt(p));
            n += 1.0;
        }
    vec4 result = n > 0.0 ? vec4(color / n, depth / n) : vec4(0.0);
    imageStore(gImagesRgba16f[pc.sssSlot0], h, result);
}
