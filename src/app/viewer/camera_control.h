#pragma once
// The viewer's cameras: fly (WASD + Q/E, right mouse button looks around) and orbit (left
// button turns about a target, wheel zooms). Tab switches between them.
#include "scene/scene.h"

struct GLFWwindow;

namespace shadel {

struct CameraControl {
    bool orbit = false;
    Camera camera;          // what is rendered
    glm::vec3 target{0.0f}; // orbit centre
    float yaw = 0.0f, pitch = 0.0f, distance = 5.0f;
    float speed = 3.0f; // fly: units per second
    double lastX = 0.0, lastY = 0.0;
    bool dragging = false;
};

// Starts from the scene's camera; the orbit target is where it looks at the scene's centre depth.
CameraControl makeCameraControl(const Camera& start, const Aabb& sceneBounds);
// Applies this frame's input (dt seconds). `mouseFree`: the UI does not want the mouse.
// Returns true when the camera moved.
bool updateCamera(CameraControl& c, GLFWwindow* window, float dt, bool mouseFree, float wheel);

} // namespace shadel
