// `shadel view` under Xvfb on lavapipe (src/app/viewer): the window shows what `shadel render`
// renders for the same camera, and the ImGui panel draws over it.
#include "gpu_test_env.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>

#include <stb/stb_image.h>

using namespace shadel;
using namespace shadel::test;

namespace {

bool haveXvfb() {
    return std::system("command -v xvfb-run >/dev/null 2>&1") == 0;
}

// Runs the viewer under a fresh Xvfb display; returns its exit code.
int runView(const std::string& args) {
    std::string cmd = "timeout 300 xvfb-run -a -s '-screen 0 1024x768x24' " +
                      std::string(SHADEL_BINARY) + " --validation view " + args + " >/dev/null";
    int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool haveXdotool() {
    return std::system("command -v xdotool >/dev/null 2>&1") == 0;
}

std::string readAll(const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::vector<uint8_t> readPng(const std::string& path, int& w, int& h) {
    int channels = 0;
    uint8_t* data = stbi_load(path.c_str(), &w, &h, &channels, 4);
    if (!data) return {};
    std::vector<uint8_t> out(data, data + size_t(w) * h * 4);
    stbi_image_free(data);
    return out;
}

} // namespace

TEST(Viewer, ScreenshotUnderXvfbMatchesRenderOfTheSameCamera) {
    SHADEL_REQUIRE(haveXvfb(), "xvfb-run (scripts/setup.sh installs xvfb)");
    std::string shot = (std::filesystem::temp_directory_path() /
                        ("shadel-view-" + std::to_string(::getpid()) + ".png"))
                           .string();
    ASSERT_EQ(runView("--scene builtin:default --size 320x180 --frames 5 --screenshot " + shot +
                      " --no-ui"),
              0);
    int w = 0, h = 0;
    std::vector<uint8_t> window = readPng(shot, w, h);
    ASSERT_EQ(w, 320);
    ASSERT_EQ(h, 180);
    RenderRun render =
        renderChecked(renderOptions("builtin:default", RenderMode::Forward, 320, 180));
    double p = psnr(window, render.frames.back().rgba);
    std::printf("[ figures ] view --no-ui screenshot vs render: %.2f dB\n", p);
    EXPECT_GE(p, 30.0);

    // With the panel: still exits cleanly (validation on), and the panel covers part of it.
    ASSERT_EQ(runView("--scene builtin:default --size 320x180 --frames 2 --screenshot " + shot), 0);
    std::vector<uint8_t> withUi = readPng(shot, w, h);
    ASSERT_EQ(withUi.size(), window.size());
    double ui = psnr(withUi, window);
    std::printf("[ figures ] view with the panel vs --no-ui: %.2f dB\n", ui);
    EXPECT_LT(ui, 30.0);
    std::filesystem::remove(shot);
}

// The viewer takes its keys from window events (a tap between two 300 ms frames is not lost):
// xdotool taps F (frame the scene), R (back to the scene's camera) and Esc (quit, exit 0) into
// the real window under Xvfb.
TEST(Viewer, KeyTapsFrameResetAndQuit) {
    SHADEL_REQUIRE(haveXvfb(), "xvfb-run (scripts/setup.sh installs xvfb)");
    SHADEL_REQUIRE(haveXdotool(), "xdotool (scripts/setup.sh installs it)");
    std::string base = (std::filesystem::temp_directory_path() /
                        ("shadel-view-keys-" + std::to_string(::getpid())))
                           .string();
    std::string script = base + ".sh", log = base + ".log";
    std::ofstream(script) << "#!/bin/sh\n"
                          << SHADEL_BINARY
                          << " --validation view --scene builtin:default --size 320x180 "
                             "--frames 0 >"
                          << log << " 2>&1 &\n"
                          << "pid=$!\n"
                          << "wid=$(timeout 240 xdotool search --sync --name 'shadel view')\n"
                          << "xdotool windowfocus --sync $wid\n"
                          << "xdotool key f; sleep 1; xdotool key r; sleep 1; xdotool key Escape\n"
                          << "wait $pid; echo \"exit $?\" >>" << log << "\n";
    std::string cmd = "timeout 300 xvfb-run -a -s '-screen 0 1024x768x24' sh " + script;
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    std::string out = readAll(log);
    EXPECT_NE(out.find("shadel view: F: the scene framed, --from "), std::string::npos) << out;
    EXPECT_NE(out.find("shadel view: R: the scene's camera, --from "), std::string::npos) << out;
    EXPECT_NE(out.find("shadel view: Esc: quit"), std::string::npos) << out;
    EXPECT_NE(out.find("0 validation errors"), std::string::npos) << out;
    EXPECT_NE(out.find("exit 0"), std::string::npos) << out;
    std::filesystem::remove(script);
    std::filesystem::remove(log);
}
