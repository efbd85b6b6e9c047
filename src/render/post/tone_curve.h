#pragma once
// The CPU side of shaders/common/tone_curve.glsl: the display curves, and the scene radiance
// a curve turns into a given display colour (a solid --background under any curve).
#include <glm/vec3.hpp>

#include "render/renderer.h"

namespace shadel {
// Exposed linear colour -> display-linear colour in [0, 1], as toneCurve in GLSL.
glm::vec3 toneCurve(glm::vec3 exposed, Tonemap curve);
// A scene colour as the display shows it, sRGB-encoded in [0, 1] (displayColor in GLSL).
glm::vec3 displayColor(glm::vec3 hdr, float exposure, Tonemap curve);
// The radiance (>= 0) whose display colour is `srgb` (clamped to what the curve can reach).
glm::vec3 radianceForDisplay(glm::vec3 srgb, float exposure, Tonemap curve);
} // namespace shadel
