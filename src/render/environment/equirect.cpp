#include "render/environment/equirect.h"

#include <algorithm>
#include <cmath>

namespace shadel {

namespace {
constexpr double kPi = 3.14159265358979323846;
}

EquirectImage makeEquirect(uint32_t width, uint32_t height, glm::vec3 fill) {
    EquirectImage image;
    image.width = width;
    image.height = height;
    image.texels.assign(size_t(width) * height, fill);
    return image;
}

glm::vec2 equirectUv(glm::vec3 d) {
    // u = 0.5 looks along +Z, u = 0.25 along +X, u = 0.75 along -X; v = 0 looks up.
    float u = 0.5f + float(std::atan2(double(-d.x), double(d.z)) / (2.0 * kPi));
    if (u >= 1.0f) u -= 1.0f;
    float v = float(std::acos(std::clamp(double(d.y), -1.0, 1.0)) / kPi);
    return {u, v};
}

glm::vec3 equirectDirection(glm::vec2 uv) {
    double phi = (double(uv.x) - 0.5) * 2.0 * kPi;
    double theta = double(uv.y) * kPi;
    double s = std::sin(theta);
    return glm::vec3(float(-s * std::sin(phi)), float(std::cos(theta)), float(s * std::cos(phi)));
}

glm::vec3 rotateToEnvironment(glm::vec3 d, float rotationDegrees) {
    double a = double(rotationDegrees) * kPi / 180.0;
    float c = float(std::cos(a)), s = float(std::sin(a));
    return {c * d.x + s * d.z, d.y, -s * d.x + c * d.z};
}

double equirectTexelSolidAngle(uint32_t width, uint32_t height, uint32_t y) {
    double t0 = kPi * double(y) / height, t1 = kPi * double(y + 1) / height;
    return 2.0 * kPi / width * (std::cos(t0) - std::cos(t1));
}

glm::vec3 sampleEquirect(const EquirectImage& image, glm::vec2 uv) {
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) uv = glm::vec2(0.5f);
    uv.x -= std::floor(uv.x); // wrap before converting to texels (no integer overflow)
    float x = uv.x * float(image.width) - 0.5f;
    float y = std::clamp(uv.y * float(image.height) - 0.5f, 0.0f, float(image.height - 1));
    float fx = std::floor(x), fy = std::floor(y);
    float tx = x - fx, ty = y - fy;
    int w = int(image.width);
    int x0 = ((int(fx) % w) + w) % w, x1 = (x0 + 1) % w;
    uint32_t y0 = uint32_t(fy), y1 = std::min(y0 + 1, image.height - 1);
    glm::vec3 top = glm::mix(image.at(uint32_t(x0), y0), image.at(uint32_t(x1), y0), tx);
    glm::vec3 bottom = glm::mix(image.at(uint32_t(x0), y1), image.at(uint32_t(x1), y1), tx);
    return glm::mix(top, bottom, ty);
}

glm::vec3 sampleEquirect(const EquirectImage& image, glm::vec3 direction) {
    return sampleEquirect(image, equirectUv(direction));
}

EquirectImage downsampleEquirect(const EquirectImage& image) {
    EquirectImage out = makeEquirect(image.width / 2, image.height / 2);
    for (uint32_t y = 0; y < out.height; ++y) {
        double w0 = equirectTexelSolidAngle(image.width, image.height, 2 * y);
        double w1 = equirectTexelSolidAngle(image.width, image.height, 2 * y + 1);
        float a = float(w0 / (2.0 * (w0 + w1))), b = float(w1 / (2.0 * (w0 + w1)));
        for (uint32_t x = 0; x < out.width; ++x)
            out.at(x, y) = a * (image.at(2 * x, 2 * y) + image.at(2 * x + 1, 2 * y)) +
                           b * (image.at(2 * x, 2 * y + 1) + image.at(2 * x + 1, 2 * y + 1));
    }
    return out;
}

EquirectImage resampleEquirect(const EquirectImage& image, uint32_t width, uint32_t height) {
    EquirectImage out = makeEquirect(width, height);
    // Taps per output texel and axis: enough to cover every source texel when shrinking.
    uint32_t kx = std::max(1u, (image.width + width - 1) / width);
    uint32_t ky = std::max(1u, (image.height + height - 1) / height);
    for (uint32_t y = 0; y < height; ++y)
        for (uint32_t x = 0; x < width; ++x) {
            glm::dvec3 sum(0.0);
            double weights = 0.0;
            for (uint32_t j = 0; j < ky; ++j) {
                float v = (float(y) + (float(j) + 0.5f) / float(ky)) / float(height);
                // Solid-angle weight of the tap's latitude.
                double w = std::max(std::sin(double(v) * kPi), 1e-6);
                for (uint32_t i = 0; i < kx; ++i) {
                    float u = (float(x) + (float(i) + 0.5f) / float(kx)) / float(width);
                    sum += w * glm::dvec3(sampleEquirect(image, glm::vec2(u, v)));
                    weights += w;
                }
            }
            out.at(x, y) = glm::vec3(sum / weights);
        }
    return out;
}

glm::dvec3 equirectEnergy(const EquirectImage& image) {
    glm::dvec3 sum(0.0);
    for (uint32_t y = 0; y < image.height; ++y) {
        glm::dvec3 row(0.0);
        for (uint32_t x = 0; x < image.width; ++x) row += glm::dvec3(image.at(x, y));
        sum += row * equirectTexelSolidAngle(image.width, image.height, y);
    }
    return sum;
}

} // namespace shadel
