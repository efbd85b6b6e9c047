// The display tone curves (the glTF Sample Viewer's, by the same names: ACES after Narkowicz,
// the default, and after Hill, Khronos PBR Neutral, linear), shared by the tonemap pass and the
// passes it is fused into. Shadel prefiltering averages supersamples in the ACES fit's space
// whatever the display curve (shaders/shadel/prefilter.glsl): a perceptual average, not the
// display's.
// And the display encoding (exposure, curve, sRGB, 8 bits), shared by the tonemap pass and the
// passes the tonemap is fused into (render/post/tonemap.h): the compute resolve, forward shading.
#ifndef SHADEL_TONE_CURVE_GLSL
#define SHADEL_TONE_CURVE_GLSL

vec3 acesFit(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

// Stephen Hill's fit of the ACES reference transforms: sRGB into the RRT's input space, the
// RRT + ODT rational fit, back to sRGB.
vec3 acesHill(vec3 x) {
    const mat3 toRrt = mat3(0.59719, 0.07600, 0.02840, 0.35458, 0.90834, 0.13383, 0.04823,
                            0.01566, 0.83777);
    const mat3 fromOdt = mat3(1.60475, -0.10208, -0.00327, -0.53108, 1.10813, -0.07276,
                              -0.07367, -0.00605, 1.07602);
    x = toRrt * x;
    x = (x * (x + 0.0245786) - 0.000090537) / (x * (0.983729 * x + 0.4329510) + 0.238081);
    return clamp(fromOdt * x, 0.0, 1.0);
}

// Khronos PBR Neutral: identity below 0.76 (after a small toe that lifts nothing above 0.08),
// a smooth shoulder above, and desaturation toward white as the shoulder compresses.
vec3 khrPbrNeutral(vec3 c) {
    const float startCompression = 0.8 - 0.04;
    const float desaturation = 0.15;
    float x = min(c.r, min(c.g, c.b));
    float offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
    c -= offset;
    float peak = max(c.r, max(c.g, c.b));
    if (peak < startCompression) return c;
    const float d = 1.0 - startCompression;
    float newPeak = 1.0 - d * d / (peak + d - startCompression);
    c *= newPeak / peak;
    float g = 1.0 - 1.0 / (desaturation * (peak - newPeak) + 1.0);
    return mix(c, vec3(newPeak), g);
}

// The display curve FrameConstants::tonemap names (TONEMAP_*), of exposed linear colour.
vec3 toneCurve(vec3 x, uint curve) {
    if (curve == TONEMAP_ACES_HILL) return acesHill(x);
    if (curve == TONEMAP_KHR_PBR_NEUTRAL) return clamp(khrPbrNeutral(x), 0.0, 1.0);
    if (curve == TONEMAP_LINEAR) return clamp(x, 0.0, 1.0);
    return acesFit(x);
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
vec3 displayColor(vec3 hdr, float exposure, uint curve) {
    return linearToSrgb(toneCurve(max(hdr, vec3(0.0)) * exposure, curve));
}

// 8 bits per channel, as an RGBA8 target quantizes; alpha 255 where geometry covers the pixel
// (the readback's coverage, FrameResult::rgba).
uint packDisplayPixel(vec3 display, bool covered) {
    uvec3 b = uvec3(clamp(display, 0.0, 1.0) * 255.0 + 0.5);
    return b.r | (b.g << 8) | (b.b << 16) | ((covered ? 255u : 0u) << 24);
}

// The same with a fractional coverage (supersampled frames): alpha = coverage x 255.
uint packDisplayPixel(vec3 display, float coverage) {
    uvec4 b = uvec4(clamp(vec4(display, coverage), 0.0, 1.0) * 255.0 + 0.5);
    return b.r | (b.g << 8) | (b.b << 16) | (b.a << 24);
}
#endif
