#pragma once
// The viewer's cameras: fly (WASD + Q/E, right mouse button looks around, Shift 4x faster, [ and
// ] halve and double the speed) and orbit (left button turns about a target, wheel zooms). Tab
// switches between them; F frames the whole scene, R returns to the scene's camera.
#include <string>

#include "scene/scene.h"

struct GLFWwindow;

namespace shadel {

struct ViewerInput;

struct CameraControl {
    bool orbit = false;
    Camera camera;          // what is rendered
    glm::vec3 target{0.0f}; // orbit centre
    float yaw = 0.0f, pitch = 0.0f, distance = 5.0f;
    float speed = 3.0f; // fly: units per second of wall time
    double lastX = 0.0, lastY = 0.0;
    bool dragging = false;
};

// Starts from the scene's camera; the orbit target is where it looks at the scene's centre depth.
CameraControl makeCameraControl(const Camera& start, const Aabb& sceneBounds);
// Applies this frame's input (dt seconds of wall time). `mouseFree`: the UI does not want the
// mouse. Returns true when the camera moved.
bool updateCamera(CameraControl& c, GLFWwindow* window, float dt, bool mouseFree,
                  const ViewerInput& input);
// Keeps the view direction and moves back until the whole scene fits the view.
void frameScene(CameraControl& c, const Aabb& sceneBounds);
// "--from X,Y,Z --look-at X,Y,Z": the camera as `shadel render` arguments.
std::string cameraArguments(const CameraControl& c);

} // namespace shadel
