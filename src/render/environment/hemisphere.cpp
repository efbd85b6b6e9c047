#include "render/environment/hemisphere.h"

#include <algorithm>
#include <cmath>

namespace shadel {

namespace {

// Irradiance / pi facing up and facing down of the radiance max(0, a + b y) (y = cos theta):
// 2 * integral of L(y) |y| dy over each half.
glm::dvec2 polarIrradiance(double a, double b) {
    const int kSteps = 512;
    glm::dvec2 e(0.0);
    for (int i = 0; i < kSteps; ++i) {
        double y = (i + 0.5) / kSteps;
        e.x += std::max(0.0, a + b * y) * y;
        e.y += std::max(0.0, a - b * y) * y;
    }
    return e * (2.0 / kSteps);
}

} // namespace

glm::vec3 hemisphereAmbient(glm::vec3 skyColor, glm::vec3 ambientColor, float ny) {
    return glm::mix(ambientColor * 0.5f, ambientColor + skyColor * 0.15f, ny * 0.5f + 0.5f);
}

EquirectImage hemisphereRadiance(glm::vec3 skyColor, glm::vec3 ambientColor, uint32_t width,
                                 uint32_t height) {
    glm::vec3 below = hemisphereAmbient(skyColor, ambientColor, -1.0f);
    glm::vec3 above = hemisphereAmbient(skyColor, ambientColor, 1.0f);
    glm::dvec3 a(0.0), b(0.0);
    for (int c = 0; c < 3; ++c) {
        // Irradiance / pi of a + b y is a + (2/3) b n.y: a is the mean, b = 3/4 of the
        // difference. Where that goes negative below, the clamped radiance is corrected until
        // the irradiance facing up and down match again.
        a[c] = 0.5 * (double(above[c]) + below[c]);
        b[c] = 0.75 * (double(above[c]) - below[c]);
        for (int i = 0; i < 64 && a[c] - std::abs(b[c]) < 0.0; ++i) {
            glm::dvec2 e = polarIrradiance(a[c], b[c]);
            double up = above[c] - e.x, down = below[c] - e.y;
            a[c] += 0.5 * (up + down);
            b[c] += 0.75 * (up - down);
        }
    }
    EquirectImage image = makeEquirect(width, height);
    const double pi = 3.14159265358979323846;
    for (uint32_t y = 0; y < height; ++y) {
        // The row's solid-angle mean of max(0, a + b cos(theta)), by sub-rows.
        glm::dvec3 sum(0.0);
        double weights = 0.0;
        for (int k = 0; k < 16; ++k) {
            double theta = pi * (y + (k + 0.5) / 16.0) / height;
            double w = std::sin(theta);
            sum += w * glm::max(a + b * std::cos(theta), glm::dvec3(0.0));
            weights += w;
        }
        glm::vec3 radiance(sum / weights);
        for (uint32_t x = 0; x < width; ++x) image.at(x, y) = radiance;
    }
    return image;
}

} // namespace shadel
