#include "render/post/tone_curve.h"

#include <algorithm>
#include <cmath>

#include <glm/mat3x3.hpp>

namespace shadel {

namespace {
glm::vec3 clamp01(glm::vec3 c) {
    return glm::clamp(c, glm::vec3(0.0f), glm::vec3(1.0f));
}

glm::vec3 acesNarkowicz(glm::vec3 x) {
    return clamp01((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f));
}

glm::vec3 acesHill(glm::vec3 x) {
    const glm::mat3 toRrt(0.59719f, 0.07600f, 0.02840f, 0.35458f, 0.90834f, 0.13383f, 0.04823f,
                          0.01566f, 0.83777f);
    const glm::mat3 fromOdt(1.60475f, -0.10208f, -0.00327f, -0.53108f, 1.10813f, -0.07276f,
                            -0.07367f, -0.00605f, 1.07602f);
    x = toRrt * x;
    x = (x * (x + 0.0245786f) - 0.000090537f) / (x * (0.983729f * x + 0.4329510f) + 0.238081f);
    return clamp01(fromOdt * x);
}

glm::vec3 khrPbrNeutral(glm::vec3 c) {
    const float startCompression = 0.8f - 0.04f, desaturation = 0.15f;
    float x = std::min(c.r, std::min(c.g, c.b));
    float offset = x < 0.08f ? x - 6.25f * x * x : 0.04f;
    c -= offset;
    float peak = std::max(c.r, std::max(c.g, c.b));
    if (peak < startCompression) return clamp01(c);
    const float d = 1.0f - startCompression;
    float newPeak = 1.0f - d * d / (peak + d - startCompression);
    c *= newPeak / peak;
    float g = 1.0f - 1.0f / (desaturation * (peak - newPeak) + 1.0f);
    return clamp01(glm::mix(c, glm::vec3(newPeak), g));
}

float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}
float linearToSrgb(float c) {
    return c < 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}
} // namespace

glm::vec3 toneCurve(glm::vec3 x, Tonemap curve) {
    switch (curve) {
    case Tonemap::AcesHill:
        return acesHill(x);
    case Tonemap::KhrPbrNeutral:
        return khrPbrNeutral(x);
    case Tonemap::Linear:
        return clamp01(x);
    case Tonemap::AcesNarkowicz:
        break;
    }
    return acesNarkowicz(x);
}

glm::vec3 displayColor(glm::vec3 hdr, float exposure, Tonemap curve) {
    glm::vec3 y = toneCurve(glm::max(hdr, glm::vec3(0.0f)) * exposure, curve);
    return {linearToSrgb(y.r), linearToSrgb(y.g), linearToSrgb(y.b)};
}

glm::vec3 radianceForDisplay(glm::vec3 srgb, float exposure, Tonemap curve) {
    srgb = clamp01(srgb);
    glm::vec3 target{srgbToLinear(srgb.r), srgbToLinear(srgb.g), srgbToLinear(srgb.b)};
    // Every curve is increasing in each channel, at most quadratic in its toe (Khronos PBR
    // Neutral's darkest channel) and mixes channels only a little (Hill), so a damped
    // multiplicative correction per channel (the square root of the ratio: it neither overshoots
    // where the curve is quadratic nor stalls where it is linear) converges. Unreachable targets
    // (above the curve's maximum) end at its shoulder.
    glm::vec3 x = target;
    for (int step = 0; step < 400; ++step) {
        glm::vec3 y = toneCurve(x, curve);
        glm::vec3 ratio = glm::sqrt((target + 1e-7f) / (y + 1e-7f));
        x = glm::min(x * glm::clamp(ratio, glm::vec3(0.5f), glm::vec3(2.0f)), glm::vec3(1e4f));
    }
    return x / std::max(exposure, 1e-12f);
}

} // namespace shadel
