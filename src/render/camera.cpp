#include "render/camera.h"

#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"
#include "core/log.h"

namespace shadel {

Camera findCamera(const Scene& scene, const std::string& name) {
    if (name.empty() && !scene.cameras.empty()) return scene.cameras.front();
    for (const Camera& c : scene.cameras)
        if (c.name == name) return c;
    if (!name.empty()) {
        std::string names;
        for (const Camera& c : scene.cameras) names += (names.empty() ? "" : ", ") + c.name;
        throw InputError(format("--camera %s: no such camera in scene %s (cameras: %s)",
                                name.c_str(), scene.name.c_str(),
                                names.empty() ? "none" : names.c_str()));
    }
    // No camera in the file: frame the bounds from the front, slightly above.
    Aabb b = scene.worldBounds();
    Camera c;
    c.name = "auto";
    glm::vec3 center = b.valid() ? b.center() : glm::vec3(0.0f);
    float radius = b.valid() ? glm::length(b.extent()) * 0.5f : 1.0f;
    radius = std::max(radius, 1e-3f);
    c.yfov = 0.8f;
    float distance = radius / std::sin(c.yfov * 0.5f);
    c.forward = glm::normalize(glm::vec3(0.0f, -0.35f, -1.0f));
    c.position = center - c.forward * distance;
    c.up = {0, 1, 0};
    c.znear = std::max(distance - radius * 1.5f, distance * 0.001f);
    c.zfar = distance + radius * 2.0f;
    return c;
}

CameraView makeCameraView(const Camera& camera, uint32_t width, uint32_t height, glm::vec2 jitter) {
    CameraView v;
    v.position = camera.position;
    v.yfov = camera.yfov;
    v.znear = camera.znear;
    v.zfar = camera.zfar;
    glm::vec3 up = camera.up;
    if (std::abs(glm::dot(glm::normalize(up), glm::normalize(camera.forward))) > 0.999f)
        up = {0, 0, 1};
    v.view = glm::lookAt(camera.position, camera.position + camera.forward, up);
    float aspect = float(width) / float(height);
    // Reversed Z: swap near and far in a [0,1] projection.
    glm::mat4 p = glm::perspectiveRH_ZO(camera.yfov, aspect, camera.zfar, camera.znear);
    p[1][1] *= -1.0f; // Vulkan's y points down in clip space
    p[2][0] += jitter.x * 2.0f / float(width);
    p[2][1] += jitter.y * 2.0f / float(height);
    v.proj = p;
    return v;
}

static float halton(uint32_t index, uint32_t base) {
    float f = 1.0f, r = 0.0f;
    while (index > 0) {
        f /= float(base);
        r += f * float(index % base);
        index /= base;
    }
    return r;
}

glm::vec2 subpixelJitter(uint32_t frame) {
    return {halton(frame + 1, 2) - 0.5f, halton(frame + 1, 3) - 0.5f};
}

std::array<glm::vec4, 6> frustumPlanes(const glm::mat4& m) {
    glm::mat4 t = glm::transpose(m);
    std::array<glm::vec4, 6> planes = {t[3] + t[0], t[3] - t[0], t[3] + t[1],
                                       t[3] - t[1], t[2],        t[3] - t[2]};
    for (glm::vec4& p : planes) p /= std::max(glm::length(glm::vec3(p)), 1e-20f);
    return planes;
}

} // namespace shadel
