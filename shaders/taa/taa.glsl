// What the temporal anti-aliasing passes share: the perceptual space they filter in and YCoCg.
#ifndef SHADEL_TAA_GLSL
#define SHADEL_TAA_GLSL

// Exposed HDR colour into [0, 1) and back (x / (1 + max)): filtering, clipping and blending in
// this space keeps one bright sample from dominating a pixel, as the display curve would.
vec3 taaCompress(vec3 c) {
    return c / (1.0 + max(c.r, max(c.g, c.b)));
}
vec3 taaExpand(vec3 c) {
    return c / max(1.0 - max(c.r, max(c.g, c.b)), 1.0 / 65504.0);
}

// YCoCg: luma and two chroma axes, where a neighbourhood's colour box is tight.
vec3 rgbToYCoCg(vec3 c) {
    return vec3(0.25 * c.r + 0.5 * c.g + 0.25 * c.b, 0.5 * c.r - 0.5 * c.b,
                -0.25 * c.r + 0.5 * c.g - 0.25 * c.b);
}
vec3 yCoCgToRgb(vec3 c) {
    return vec3(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z);
}

#endif
