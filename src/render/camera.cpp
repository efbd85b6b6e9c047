#include "render/camera.h"

#include <algorithm>
#include <cmath>

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
    c.automatic = true;
    return c;
}

// An orthographic camera is drawn as a telephoto perspective one from far behind it: every
// pass, the view-driven density and the decoupled MIP estimates assume a perspective projection.
// A point at depth z in front of the orthographic camera then shows at back / (back + z) of its
// size, so the distance is 256 x the far plane (0.4% at the far plane), at least 256 view
// heights, and at most 4096 view heights, where float positions keep 1e-3 of the view's height.
float orthoBackoff(const Camera& camera) {
    float h = camera.orthoHalfHeight;
    return std::clamp(256.0f * std::max(camera.zfar, h), 256.0f * h, 4096.0f * h);
}

Camera perspectiveEquivalent(const Camera& camera) {
    if (!(camera.orthoHalfHeight > 0.0f)) return camera;
    Camera c = camera;
    float back = orthoBackoff(camera);
    c.position = camera.position - camera.forward * back;
    c.yfov = 2.0f * std::atan(camera.orthoHalfHeight / back);
    c.znear = back + camera.znear;
    c.zfar = back + camera.zfar;
    c.orthoHalfHeight = 0.0f;
    return c;
}

CameraView makeCameraView(const Camera& ortho, uint32_t width, uint32_t height, glm::vec2 jitter) {
    Camera camera = perspectiveEquivalent(ortho);
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

CameraPath parseCameraPath(const std::string& text) {
    if (text == "static") return CameraPath::Static;
    if (text == "orbit") return CameraPath::Orbit;
    if (text == "walk") return CameraPath::Walk;
    throw InputError(format("--camera-path %s: expected static, orbit or walk", text.c_str()));
}

Camera cameraOnPath(const Camera& start, CameraPath path, uint32_t frame, uint32_t frames,
                    const Aabb& sceneBounds) {
    if (path == CameraPath::Static || frames < 2) return start;
    float t = float(frame) / float(frames - 1);
    glm::vec3 center = sceneBounds.valid() ? sceneBounds.center() : glm::vec3(0.0f);
    float radius =
        sceneBounds.valid() ? std::max(glm::length(sceneBounds.extent()) * 0.5f, 1e-3f) : 1.0f;
    glm::vec3 forward = glm::normalize(start.forward);
    Camera c = start;
    if (path == CameraPath::Orbit) {
        // Pivot: the point on the view ray nearest the scene's centre (at least 10% of the
        // scene's radius ahead), so the orbit keeps the scene in view.
        float ahead = std::max(glm::dot(center - start.position, forward), 0.1f * radius);
        glm::vec3 pivot = start.position + forward * ahead;
        glm::mat3 turn = glm::mat3(
            glm::rotate(glm::mat4(1.0f), glm::radians(40.0f) * t, glm::vec3(0.0f, 1.0f, 0.0f)));
        c.position = pivot + turn * (start.position - pivot);
        c.forward = turn * forward;
    } else {
        glm::vec3 flat = glm::vec3(forward.x, 0.0f, forward.z);
        flat = glm::length(flat) > 1e-4f ? glm::normalize(flat) : glm::vec3(0.0f, 0.0f, -1.0f);
        c.position = start.position + flat * (0.05f * radius * t);
        float sway = glm::radians(5.0f) * std::sin(t * 6.2831853f);
        c.forward =
            glm::mat3(glm::rotate(glm::mat4(1.0f), sway, glm::vec3(0.0f, 1.0f, 0.0f))) * forward;
    }
    return c;
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
