#version 460
// Character outline and occlusion tint: on the pixels a character covers, seen or
// hidden behind something (stencil EQUAL to STENCIL_CHARACTER), an outline on the inside of the
// silhouette where a neighbour within the radius is not a character, and a tint where the
// character is hidden (the centre sample decides). The full-screen version runs every pixel and
// branches on the mask. Early fragment tests: see water_composite.frag.
#define SCREEN_SPACE_FRAGMENT // no tile lists here
#include "screenspace/screen_space.glsl"
#include "stencil/stencil_bits.h"

layout(early_fragment_tests) in;

const vec3 kOutlineColor = vec3(4.0, 2.6, 0.3);
const vec3 kHiddenTint = vec3(0.35, 0.75, 2.2);
#define HIDDEN_TINT_WEIGHT 0.55

float maskAt(ivec2 p) {
    p = clamp(p, ivec2(0), ivec2(pc.width, pc.height) - 1);
    return fetchTextureUniform(pc.characterMaskSlot, p, 0).r;
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float centre = maskAt(p);
    if (centre == 0.0) return; // only the full-screen version gets here
    int radius = max(1, int(pc.height) / 360); // 2 pixels at 720 lines
    // Eight taps on the circle of the radius (axes and diagonals) rather than the whole disc:
    // at 720 lines 8 fetches instead of 13 for an outline that differs only at thin features.
    int diagonal = max(1, int(float(radius) * 0.7071 + 0.5));
    const ivec2 dirs[8] = ivec2[8](ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1),
                                   ivec2(1, 1), ivec2(-1, 1), ivec2(1, -1), ivec2(-1, -1));
    bool edge = false;
    for (int k = 0; k < 8; ++k)
        edge = edge || maskAt(p + dirs[k] * (k < 4 ? radius : diagonal)) == 0.0;
    vec4 color = imageLoad(gImagesRgba16f[pc.hdrSlot], p);
    if (edge)
        color.rgb = kOutlineColor;
    else if (centre < 0.75) // hidden: CHARACTER_MASK_HIDDEN
        color.rgb = mix(color.rgb, kHiddenTint, HIDDEN_TINT_WEIGHT);
    imageStore(gImagesRgba16f[pc.hdrSlot], p, color);
}
