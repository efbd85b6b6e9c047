// Separable subsurface scattering at half resolution (shared by its passes).
#ifndef SHADEL_SSS_GLSL
#define SHADEL_SSS_GLSL
#include "screenspace/screen_space.glsl"

#define SSS_TAPS 6              // each side of the centre
#define SSS_WIDTH_METRES 0.035  // how far light travels under skin (the red channel's reach)
#define SSS_DEPTH_FALLOFF 0.05  // metres: taps farther in depth belong to another surface

uvec2 halfSize() { return uvec2((pc.width + 1u) / 2u, (pc.height + 1u) / 2u); }

// Whether a half-resolution texel holds skin, from the G-buffer (always this frame's: texels of
// tiles without skin are not written when classification is on, so their contents are stale).
bool halfTexelIsSkin(ivec2 h) {
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 2; ++x) {
            ivec2 p = min(h * 2 + ivec2(x, y), ivec2(pc.width, pc.height) - 1);
            if ((pixelFlagsAt(p) & PIXEL_SKIN) != 0u) return true;
        }
    return false;
}
#endif
