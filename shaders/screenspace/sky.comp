#version 460
// The sky pass: every sky pixel of the tile gets the sky along its view ray. Permutation 1
// (TILE_LIST_SKY: the classification saw no surface in the tile) writes without reading the
// G-buffer; permutation 0 tests each pixel (tiles with an edge, or classification off).
#include "screenspace/screen_space.glsl"
#include "background/background.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(constant_id = 0) const uint ALL_SKY = 0u;

void main() {
    uvec2 tile = currentTile(pc.tiles, pc.listOffset);
    ivec2 p = ivec2(tile * TILE_SIZE + gl_LocalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) return;
    if (ALL_SKY == 0u && (pixelFlagsAt(p) & PIXEL_SURFACE) != 0u) return;
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    vec3 sky = backgroundAt(f, vec2(p) + 0.5);
    imageStore(gImagesRgba16f[pc.hdrSlot], p, vec4(sky, 0.0));
}
