// `shadel view`: the window's starting settings come from the option table
// (app/option_table.h); the flags here are the viewer's own.
#include <memory>

#include "app/option_table.h"
#include "app/subcommands.h"
#include "app/viewer/viewer.h"

namespace shadel {

Subcommand addViewCommand(CLI::App& app) {
    struct ViewFlags {
        ViewOptions options;
        SettingFlags settings;
        std::string threads = "auto";
    };
    auto f = std::make_shared<ViewFlags>();
    ViewOptions& vo = f->options;
    CLI::App* c = app.add_subcommand("view", "open a window: fly/orbit cameras, forward/decoupled, "
                                             "debug views, per-pass timings (Xvfb works)");
    c->add_option("--scene", vo.scene, "builtin:NAME | FILE.gltf | FILE.glb")
        ->capture_default_str();
    c->add_option("--camera", vo.camera, "camera name (default: the scene's first)");
    c->add_option("--frames", vo.frames, "quit after N frames (0: when the window closes)")
        ->capture_default_str();
    c->add_option("--screenshot", vo.screenshot,
                  "FILE.png: the window's last frame (with --frames), or on the UI's button");
    c->add_option("--threads", f->threads, "auto | N: threads recording the frame's passes")
        ->capture_default_str();
    c->add_flag("--no-ui", vo.noUi, "no ImGui panel (screenshots show only the frame)");
    c->add_option("--cache-dir", vo.cacheDir, "bake cache directory");
    c->add_option("--shader-source", vo.shaderSource,
                  "GLSL folder watched for hot reload (recompiled with glslc); empty: off")
        ->capture_default_str();
    addSettingFlags(*c, kViewCommand, f->settings);
    return {c, [f](const GlobalFlags& g) {
                ViewOptions& o = f->options;
                applySettingFlags(f->settings, {o, o.addDefaultSun});
                o.allowExternalFiles = g.allowExternalFiles;
                o.threads = parseThreads(f->threads);
                o.cacheLimitBytes = g.cacheLimitBytes;
                o.pipelineCacheFolder = g.pipelineCacheFolder();
                return runViewer(o, g.deviceDesc());
            }};
}

} // namespace shadel
