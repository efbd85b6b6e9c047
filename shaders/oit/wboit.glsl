// Weighted blended order-independent transparency with additiveness (after McGuire &
// Bavoil 2013). Shared by every pass that writes transparent fragments (forward accumulation,
// decoupled reconstruction) and by the composite, so they all use one definition.
#ifndef SHADEL_WBOIT_GLSL
#define SHADEL_WBOIT_GLSL
#include "common/bindless.glsl"

// A transparent fragment: premultiplied colour, coverage and how much of it is additive.
// Opacity (what it hides behind it) is coverage * (1 - additiveness): an additive fragment
// covers without hiding, so it adds its colour (premultiplied alpha with alpha 0).
struct TransparentFragment {
    vec3 premultiplied;
    float coverage;
    float additiveness;
};

TransparentFragment transparentFragment(vec3 shaded, float alpha, float additiveness) {
    TransparentFragment t;
    t.coverage = clamp(alpha, 0.0, 1.0);
    t.premultiplied = max(shaded, vec3(0.0)) * t.coverage;
    t.additiveness = clamp(additiveness, 0.0, 1.0);
    return t;
}

float transparentOpacity(TransparentFragment t) { return t.coverage * (1.0 - t.additiveness); }

// A fixed canonical depth range: the weights are tuned once, whatever the camera's near/far.
const float WBOIT_CANONICAL_NEAR = 0.5;
const float WBOIT_CANONICAL_FAR = 300.0;
const float WBOIT_PRECISION_SCALAR = 1e4;
// Shifts the depth term up instead of clamping it low: far layers keep their depth ordering
// (a low clamp would make every far layer weigh the same) and cannot underflow.
const float WBOIT_WEIGHT_BIAS = 5.0;
const float WBOIT_MAX_WEIGHT = 300.0;
const float WBOIT_OPACITY_SENSITIVITY = 3.0; // only nearly invisible layers are down-weighted
// Stored weights are scaled by this (it cancels in the weighted average) so that 300 x a colour
// of 100 leaves FP16 room for ~30 such layers per pixel.
const float WBOIT_STORAGE_SCALE = 1.0 / 16.0;
const float WBOIT_MAX_COLOR = 100.0;

// w = min(1e4 b^3 + bias, 300) a^3 with a from the fragment's coverage (additive layers
// included, as emission is: a purely additive layer has opacity
// 0 but must still weigh) and b = 1 - canonical depth.
float wboitWeight(float coverage, float viewDepth) {
    const float n = WBOIT_CANONICAL_NEAR, fa = WBOIT_CANONICAL_FAR;
    float canonical = clamp(fa / (fa - n) - fa * n / (max(viewDepth, 1e-6) * (fa - n)), 0.0, 1.0);
    float b = 1.0 - canonical;
    float a = clamp(coverage * WBOIT_OPACITY_SENSITIVITY, 0.0, 1.0);
    float w = min(WBOIT_PRECISION_SCALAR * b * b * b + WBOIT_WEIGHT_BIAS, WBOIT_MAX_WEIGHT);
    return w * a * a * a * WBOIT_STORAGE_SCALE;
}

// What a fragment writes to the two targets (blend states in render/oit/oit.cpp):
// accumulation += (premultiplied * w, coverage * w); revealage.r *= 1 - opacity;
// revealage.g *= 1 - opacity of plain alpha layers only (additiveness 0);
// revealage.a += coverage * additiveness.
void wboitOutputs(TransparentFragment t, float viewDepth, out vec4 accum, out vec4 reveal) {
    float w = wboitWeight(t.coverage, viewDepth);
    float opacity = transparentOpacity(t);
    accum = vec4(min(t.premultiplied, vec3(WBOIT_MAX_COLOR)) * w, t.coverage * w);
    reveal = vec4(opacity, t.additiveness == 0.0 ? opacity : 0.0, 0.0,
                  t.coverage * t.additiveness);
}

// The composite: C = sum(P w) / sum(coverage w) is the coverage-weighted mean colour (McGuire),
// scaled by how much the layers cover in total: 1 - R for what hides (R = revealage) plus the
// additiveness A (the summed coverage of additive layers: n layers of one colour c add n c).
// A counts less where plain alpha layers may hide it: mix(A / 4, A, G), with G
// the revealage of the additiveness-0 layers alone (R would also dim an
// additive layer by its own opacity).
// final = C ((1 - R) + mix(A / 4, A, G)) + D R. Limits: all additive (R = 1) is exactly the
// sum of the layers; no additiveness is exactly McGuire's WBOIT; a single layer of any
// additiveness is exact. Dividing by the plain sum of weights instead of coverage-weighted
// ones would darken stacked alpha layers (two 50% layers of colour c would give 0.5 c instead
// of 0.75 c) and need an amplification to hide it; this form needs no max(., 1) floor.
vec4 wboitComposite(vec4 accum, vec4 reveal) {
    float revealage = clamp(reveal.r, 0.0, 1.0);
    float alphaRevealage = clamp(reveal.g, 0.0, 1.0);
    float additive = max(reveal.a, 0.0);
    if (accum.a <= 0.0) return vec4(0.0, 0.0, 0.0, 1.0 - revealage);
    vec3 mean = accum.rgb / accum.a;
    if (any(isinf(accum.rgb)) || any(isnan(mean))) mean = vec3(100.0); // overflow: white, not NaN
    float amount = (1.0 - revealage) + additive * mix(0.25, 1.0, alphaRevealage);
    return vec4(mean * amount, 1.0 - revealage); // blended: dst = rgb + dst * revealage
}

// View depth (distance along the camera's axis) of a world position.
float viewDepthOf(FrameConstants f, vec3 worldPosition) {
    return -(f.view * vec4(worldPosition, 1.0)).z;
}
#endif
