#include "app/viewer/camera_control.h"

#include <algorithm>
#include <cmath>

#include <GLFW/glfw3.h>

#include "app/viewer/viewer_input.h"
#include "core/log.h"

namespace shadel {

namespace {
glm::vec3 direction(float yaw, float pitch) {
    return {std::cos(pitch) * std::sin(yaw), std::sin(pitch), -std::cos(pitch) * std::cos(yaw)};
}
void anglesOf(glm::vec3 forward, float& yaw, float& pitch) {
    forward = glm::normalize(forward);
    pitch = std::asin(std::clamp(forward.y, -1.0f, 1.0f));
    yaw = std::atan2(forward.x, -forward.z);
}
} // namespace

CameraControl makeCameraControl(const Camera& start, const Aabb& sceneBounds) {
    CameraControl c;
    c.camera = start;
    anglesOf(start.forward, c.yaw, c.pitch);
    glm::vec3 centre = sceneBounds.valid() ? sceneBounds.center() : start.position + start.forward;
    c.distance = std::max(glm::dot(centre - start.position, glm::normalize(start.forward)), 0.5f);
    c.target = start.position + glm::normalize(start.forward) * c.distance;
    float extent = sceneBounds.valid() ? glm::length(sceneBounds.extent()) : 10.0f;
    c.speed = std::max(extent * 0.05f, 0.1f); // the scene's diagonal in 20 s
    return c;
}

bool updateCamera(CameraControl& c, GLFWwindow* window, float dt, bool mouseFree,
                  const ViewerInput& input) {
    // A long frame (compiling, reshading) must not turn one held key into a jump.
    dt = std::min(dt, 0.25f);
    const float wheel = input.wheel;
    double x = 0, y = 0;
    glfwGetCursorPos(window, &x, &y);
    float dx = float(x - c.lastX), dy = float(y - c.lastY);
    c.lastX = x, c.lastY = y;
    bool moved = false;
    int button = c.orbit ? GLFW_MOUSE_BUTTON_LEFT : GLFW_MOUSE_BUTTON_RIGHT;
    bool down = mouseFree && glfwGetMouseButton(window, button) == GLFW_PRESS;
    if (down && c.dragging && (dx != 0 || dy != 0)) {
        c.yaw += dx * 0.005f;
        c.pitch = std::clamp(c.pitch - dy * 0.005f, -1.5f, 1.5f);
        moved = true;
    }
    c.dragging = down;
    glm::vec3 forward = direction(c.yaw, c.pitch);
    if (c.orbit) {
        if (mouseFree && wheel != 0.0f) {
            c.distance = std::max(c.distance * std::pow(0.9f, wheel), 0.2f);
            moved = true;
        }
        if (moved) c.camera.position = c.target - forward * c.distance;
    } else {
        glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0, 1, 0)));
        glm::vec3 step(0.0f);
        auto key = [&](int k) { return !input.uiWantsKeyboard && input.down(k); };
        if (!input.uiWantsKeyboard && input.tapped(GLFW_KEY_LEFT_BRACKET)) c.speed *= 0.5f;
        if (!input.uiWantsKeyboard && input.tapped(GLFW_KEY_RIGHT_BRACKET)) c.speed *= 2.0f;
        if (key(GLFW_KEY_W)) step += forward;
        if (key(GLFW_KEY_S)) step -= forward;
        if (key(GLFW_KEY_D)) step += right;
        if (key(GLFW_KEY_A)) step -= right;
        if (key(GLFW_KEY_E)) step.y += 1.0f;
        if (key(GLFW_KEY_Q)) step.y -= 1.0f;
        if (glm::dot(step, step) > 0.0f) {
            float fast = key(GLFW_KEY_LEFT_SHIFT) ? 4.0f : 1.0f;
            c.camera.position += glm::normalize(step) * c.speed * fast * dt;
            moved = true;
        }
        c.target = c.camera.position + forward * c.distance;
    }
    if (moved) { // untouched, the scene's camera is rendered exactly as `shadel render` does
        c.camera.forward = forward;
        c.camera.up = glm::vec3(0, 1, 0);
    }
    return moved;
}

void frameScene(CameraControl& c, const Aabb& sceneBounds) {
    if (!sceneBounds.valid()) return;
    glm::vec3 forward = direction(c.yaw, c.pitch);
    float radius = std::max(0.5f * glm::length(sceneBounds.extent()), 1e-3f);
    float halfFov = 0.5f * (c.camera.yfov > 0.0f ? c.camera.yfov : 0.8f);
    c.distance = radius / std::sin(halfFov) * 1.05f;
    c.target = sceneBounds.center();
    c.camera.position = c.target - forward * c.distance;
    c.camera.forward = forward;
    c.camera.up = glm::vec3(0, 1, 0);
}

std::string cameraArguments(const CameraControl& c) {
    glm::vec3 p = c.camera.position, t = c.camera.position + glm::normalize(c.camera.forward) *
                                                                 std::max(c.distance, 1e-3f);
    return format("--from %.3g,%.3g,%.3g --look-at %.3g,%.3g,%.3g", double(p.x), double(p.y),
                  double(p.z), double(t.x), double(t.y), double(t.z));
}

} // namespace shadel
