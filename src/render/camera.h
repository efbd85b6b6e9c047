#pragma once
// Camera matrices: reversed-Z perspective (depth 1 at the near plane, 0 at the far plane), with
// an optional sub-pixel jitter.
#include <array>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace shadel {

struct CameraView {
    glm::mat4 view{1.0f};
    glm::mat4 proj{1.0f};
    glm::vec3 position{0.0f};
    float yfov = 0.8f, znear = 0.05f, zfar = 500.0f;
};

// Picks the camera named `name` (empty = the scene's first; a scene without cameras gets one
// framing its bounds). Throws InputError naming the camera when it does not exist.
Camera findCamera(const Scene& scene, const std::string& name);
// Orthographic cameras become their telephoto perspective equivalent (see camera.cpp).
Camera perspectiveEquivalent(const Camera& camera);
CameraView makeCameraView(const Camera& camera, uint32_t width, uint32_t height,
                          glm::vec2 jitterPixels = glm::vec2(0.0f));
// Deterministic camera motion over a run (`--camera-path`), so reuse and stability are measured
// on moving frames: static keeps the camera; orbit turns it 40 degrees about a vertical axis
// through the point it looks at; walk moves it forward by 5% of the scene's radius with a
// gentle side-to-side look.
enum class CameraPath { Static, Orbit, Walk };
CameraPath parseCameraPath(const std::string& text); // throws InputError naming the flag
Camera cameraOnPath(const Camera& start, CameraPath path, uint32_t frame, uint32_t frames,
                    const Aabb& sceneBounds);
// Sub-pixel jitter for frame i (Halton 2,3), in pixels in [-0.5, 0.5).
glm::vec2 subpixelJitter(uint32_t frame);
// World-space planes (inside: dot(n, p) + d >= 0) of a view-projection matrix, [0,1] depth.
std::array<glm::vec4, 6> frustumPlanes(const glm::mat4& viewProj);

} // namespace shadel
