#pragma once
// The viewer's keyboard and wheel input, from GLFW's events rather than polled once per frame:
// a frame on a CPU device takes 150-400 ms, and a key tapped between two polls would be lost.
// Installed before the UI (ImGui's GLFW backend then chains to these callbacks, so the panel
// still gets the wheel and the keys).
#include <set>
#include <vector>

struct GLFWwindow;

namespace shadel {

struct ViewerInput {
    std::vector<int> pressed; // keys pressed since the last frame, in order (taps included)
    std::set<int> held;       // keys down now
    float wheel = 0.0f;       // wheel steps since the last frame
    bool uiWantsKeyboard = false;
    // Down now, or pressed and released again since the last frame.
    bool down(int key) const;
    bool tapped(int key) const;
};

// Routes the window's key and scroll events into `input` (which must outlive the window).
void installViewerInput(GLFWwindow* window, ViewerInput& input);
// Starts the next frame's input: forgets the presses and the wheel, keeps what is held.
void nextFrameInput(ViewerInput& input);

} // namespace shadel
