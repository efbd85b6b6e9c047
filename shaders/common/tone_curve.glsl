// The display tone curve (ACES fit), shared by the tonemap pass and by shadel prefiltering, which
// averages supersamples where the resolve does: after the curve (see shaders/shadel/prefilter.glsl).
// And the display encoding (exposure, curve, sRGB, 8 bits), shared by the tonemap pass and the
// passes the tonemap is fused into (render/post/tonemap.h): the compute resolve, forward shading.
#ifndef SHADEL_TONE_CURVE_GLSL
#define SHADEL_TONE_CURVE_GLSL

vec3 acesFit(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

// The x >= 0 with acesFit(x) = y, for y in [0, 0.999] (the curve only approaches ~1.03).
vec3 acesFitInverse(vec3 y) {
    y = clamp(y, vec3(0.0), vec3(0.999));
    vec3 a = 2.43 * y - 2.51, b = 0.59 * y - 0.03, c = 0.14 * y;
    return max((-b - sqrt(max(b * b - 4.0 * a * c, 0.0))) / (2.0 * a), 0.0);
}

vec3 linearToSrgb(vec3 c) {
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

// A scene colour as the display shows it (sRGB-encoded, in [0, 1]).
vec3 displayColor(vec3 hdr, float exposure) {
    return linearToSrgb(acesFit(max(hdr, vec3(0.0)) * exposure));
}

// 8 bits per channel, as an RGBA8 target quantizes; alpha 255 where geometry covers the pixel
// (the readback's coverage, FrameResult::rgba).
uint packDisplayPixel(vec3 display, bool covered) {
    uvec3 b = uvec3(clamp(display, 0.0, 1.0) * 255.0 + 0.5);
    return b.r | (b.g << 8) | (b.b << 16) | ((covered ? 255u : 0u) << 24);
}
#endif
