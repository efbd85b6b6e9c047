#pragma once
// `shadel view`: the renderer in a window (GLFW + Dear ImGui) with fly and orbit cameras, the
// forward/decoupled switch, the debug views, the per-pass timing graph and the stats. Headless
// CI runs it under Xvfb: `--frames N --screenshot FILE.png --no-ui` quits after N frames.
#include <string>

#include "render/renderer.h"
#include "rhi/device.h"

namespace shadel {

// The settings the window starts from (the option table sets them: --size is the window's,
// --mode the panel's first choice) and the viewer's own options.
struct ViewOptions : RenderSettings {
    std::string scene = "builtin:default";
    std::string camera;
    bool addDefaultSun = true; // --sun auto|off
    uint32_t frames = 0;       // 0 = until the window closes
    std::string screenshot;    // PNG of the window's last frame (with --frames) or on request
    bool noUi = false;
    uint32_t threads = 0; // --threads: recording threads (0 = auto)
    // Hot reload: the GLSL folder watched (default: the source tree's shaders/); empty = off.
    std::string shaderSource = SHADEL_SHADER_SOURCE_DIR;
    bool allowExternalFiles = false;
    uint64_t cacheLimitBytes = 4ull << 30;
    std::string pipelineCacheFolder; // where the pipeline cache is kept ("" = in memory only)
};

// Returns the process exit code (4 when validation errors or shader asserts happened).
int runViewer(const ViewOptions& options, DeviceDesc device);

} // namespace shadel
