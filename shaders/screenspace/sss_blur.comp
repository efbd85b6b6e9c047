#version 460
// Subsurface scattering, steps 2 and 3: a separable blur of the half-resolution skin lighting,
// horizontal (DIRECTION 0: sssSlot0 -> sssSlot1) then vertical (1: sssSlot1 -> sssSlot0). Red
// scatters farthest, blue least (per-channel Gaussian widths); taps on other surfaces (not skin,
// or too far in depth) are left out and the weights renormalised. The kernel spans a fixed
// width in metres, so it shrinks with distance.
#include "screenspace/sss.glsl"

layout(local_size_x = 4, local_size_y = 4) in;
layout(constant_id = 0) const uint DIRECTION = 0u;

void main() {
    uvec2 tile = currentTile(pc.tiles, pc.listOffset);
    ivec2 h = ivec2(tile * (TILE_SIZE / 2u) + gl_LocalInvocationID.xy);
    ivec2 size = ivec2(halfSize());
    if (h.x >= size.x || h.y >= size.y) return;
    uint src = DIRECTION == 0u ? pc.sssSlot0 : pc.sssSlot1;
    uint dst = DIRECTION == 0u ? pc.sssSlot1 : pc.sssSlot0;
    if (!halfTexelIsSkin(h)) {
        imageStore(gImagesRgba16f[dst], h, vec4(0.0));
        return;
    }
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    vec4 centre = imageLoad(gImagesRgba16f[src], h);
    // Half-resolution texels per metre at this depth, and the step between taps.
    float texelsPerMetre = f.proj[1][1] * float(size.y) * 0.5 / max(centre.a, 1e-3);
    float stepTexels = SSS_WIDTH_METRES * texelsPerMetre / float(SSS_TAPS);
    const vec3 sigma = vec3(1.0, 0.5, 0.3) * float(SSS_TAPS) * 0.5;
    ivec2 axis = DIRECTION == 0u ? ivec2(1, 0) : ivec2(0, 1);
    vec3 sum = vec3(0.0), weights = vec3(0.0);
    for (int k = -SSS_TAPS; k <= SSS_TAPS; ++k) {
        ivec2 q = clamp(h + axis * int(round(float(k) * stepTexels)), ivec2(0), size - 1);
        if (k != 0 && !halfTexelIsSkin(q)) continue;
        vec4 tap = k == 0 ? centre : imageLoad(gImagesRgba16f[src], q);
        if (abs(tap.a - centre.a) > SSS_DEPTH_FALLOFF) continue;
        vec3 w = exp(-0.5 * float(k * k) / (sigma * sigma));
        sum += tap.rgb * w;
        weights += w;
    }
    imageStore(gImagesRgba16f[dst], h, vec4(sum / weights, centre.a));
}
