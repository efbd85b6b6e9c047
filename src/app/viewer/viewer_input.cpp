#include "app/viewer/viewer_input.h"

#include <algorithm>

#include <GLFW/glfw3.h>

namespace shadel {

namespace {
ViewerInput* gInput = nullptr; // one viewer window per process
} // namespace

bool ViewerInput::down(int key) const {
    return held.count(key) || tapped(key);
}

bool ViewerInput::tapped(int key) const {
    return std::find(pressed.begin(), pressed.end(), key) != pressed.end();
}

void installViewerInput(GLFWwindow* window, ViewerInput& input) {
    gInput = &input;
    glfwSetKeyCallback(window, [](GLFWwindow*, int key, int, int action, int) {
        if (!gInput || key == GLFW_KEY_UNKNOWN) return;
        if (action == GLFW_PRESS) {
            gInput->pressed.push_back(key);
            gInput->held.insert(key);
        } else if (action == GLFW_RELEASE) {
            gInput->held.erase(key);
        }
    });
    glfwSetScrollCallback(window, [](GLFWwindow*, double, double y) {
        if (gInput) gInput->wheel += float(y);
    });
}

void nextFrameInput(ViewerInput& input) {
    input.pressed.clear();
    input.wheel = 0.0f;
}

} // namespace shadel
