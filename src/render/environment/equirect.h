#pragma once
// Equirectangular (latitude-longitude) images of radiance and the one direction convention every
// environment map of the renderer uses, in C++ here and in GLSL in
// shaders/environment/environment.glsl.
//
// The convention is the Khronos glTF Sample Viewer's at its default environment rotation (90
// degrees about +Y), so one .hdr file lights both renderers the same way: row 0 is the top of
// the file and looks up (+Y), the middle column looks along +Z, u grows toward -X (left of +Z
// seen from inside, with +Y up: the image is not mirrored). In the Sample Viewer's terms,
// shadel's rotation r degrees is its environmentRotation 90 + r (both turn the environment the
// same way about +Y).
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace shadel {

// The Sample Viewer's environmentRotation that equals shadel's rotation 0.
constexpr float kSampleViewerRotationOffsetDegrees = 90.0f;

// Linear RGB radiance, row-major, row 0 looking up (v = 0), texel centres at (i + 0.5) / size.
struct EquirectImage {
    uint32_t width = 0, height = 0;
    std::vector<glm::vec3> texels;

    glm::vec3& at(uint32_t x, uint32_t y) { return texels[size_t(y) * width + x]; }
    const glm::vec3& at(uint32_t x, uint32_t y) const { return texels[size_t(y) * width + x]; }
};

EquirectImage makeEquirect(uint32_t width, uint32_t height, glm::vec3 fill = glm::vec3(0.0f));

// Texture coordinates of a unit direction (u in [0, 1), v in [0, 1]) and back.
glm::vec2 equirectUv(glm::vec3 direction);
glm::vec3 equirectDirection(glm::vec2 uv);
// The environment's frame from the world's: the rotation about +Y by the environment rotation
// (the same sense as the Sample Viewer's environmentRotation).
glm::vec3 rotateToEnvironment(glm::vec3 direction, float rotationDegrees);

// Solid angle of one texel of row y (every texel of a row covers the same).
double equirectTexelSolidAngle(uint32_t width, uint32_t height, uint32_t y);

// Bilinear lookup: u wraps, v stays inside the first and last rows' centres.
glm::vec3 sampleEquirect(const EquirectImage& image, glm::vec2 uv);
glm::vec3 sampleEquirect(const EquirectImage& image, glm::vec3 direction);

// Half the width and height, each texel the solid-angle weighted mean of its 2x2 sources (so the
// radiant energy, the sum of radiance times solid angle, is kept). Width and height must be even.
EquirectImage downsampleEquirect(const EquirectImage& image);
// Resampled to width x height: a supersampled area mean when shrinking, bilinear when growing.
EquirectImage resampleEquirect(const EquirectImage& image, uint32_t width, uint32_t height);

// Sum of radiance times texel solid angle over the image (radiant energy per unit area, W/m^2
// in whatever units the radiance has).
glm::dvec3 equirectEnergy(const EquirectImage& image);

} // namespace shadel
