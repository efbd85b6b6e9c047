// The display tone curve (ACES fit), shared by the tonemap pass and by shadel prefiltering, which
// averages supersamples where the resolve does: after the curve (see shaders/shadel/prefilter.glsl).
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
#endif
