// `shadel render`: the renderer's settings from the option table (app/option_table.h), the
// command's own flags, and the summary line it prints.
#include <algorithm>
#include <cstdio>
#include <memory>

#include "app/capture_output.h"
#include "app/cli_validate.h"
#include "app/commands.h"
#include "app/option_table.h"
#include "app/subcommands.h"
#include "core/error.h"
#include "core/log.h"

namespace shadel {
namespace {

// The flags' text, parsed once the command line is read.
struct RenderFlags {
    RenderOptions options;
    SettingFlags settings;
    std::string from, lookAt, jitter = "none", skinning = "gpu", timing = "auto", threads = "auto",
                              density = "auto", cameraPath = "static", cameraCut,
                              giLocalVolumes = "on", stencilEffects = "off", streaming = "layered",
                              textureCompression = "bc", captures;
    double time = -1.0, timeStep = 0.0;
    CLI::Option* instances = nullptr;
};

void addCameraFlags(CLI::App& c, RenderFlags& f) {
    RenderOptions& ro = f.options;
    c.add_option("--frames", ro.frames, "frames to render")->capture_default_str();
    c.add_option("--camera", ro.camera,
                 "camera name (default: the scene's first; auto: frame the scene)");
    c.add_option("--from", f.from, "X,Y,Z: camera position (aims at the scene's centre)")
        ->check(finiteVec3(kCoordinateRange));
    c.add_option("--look-at", f.lookAt, "X,Y,Z: the point the camera aims at")
        ->check(finiteVec3(kCoordinateRange));
    c.add_option("--time", f.time,
                 "SECONDS: pose glTF animations (node TRS, morph weights, skins) at this time")
        ->check(finiteInRange(kTimeRange));
    c.add_option("--skinning", f.skinning,
                 "gpu|cpu: skinned glTF meshes skinned by a compute pass before every view "
                 "(default) or by the importer on the CPU");
    c.add_option("--time-step", f.timeStep,
                 "SECONDS: animated playback over --frames: frame i posed at --time (default 0) "
                 "+ i * SECONDS (node TRS, morph weights, skins)")
        ->check(finiteInRange(kTimeStepRange));
    c.add_option("--fov", ro.cameraOverrides.fovDegrees,
                 "vertical field of view in degrees (default: the camera's)")
        ->check(finiteInRange(kFovRange));
    c.add_option("--jitter", f.jitter, "none | subpixel: sub-pixel camera offsets between frames")
        ->capture_default_str();
    c.add_option("--camera-path", f.cameraPath,
                 "static | orbit | walk: camera motion over --frames")
        ->capture_default_str();
    c.add_option("--camera-cut", f.cameraCut,
                 "CAMERA@FRAME: from FRAME on, the camera path starts from the scene's camera "
                 "CAMERA (a cut; e.g. builtin:textures back@30)");
}

void addOutputFlags(CLI::App& c, RenderFlags& f) {
    RenderOptions& ro = f.options;
    c.add_option("--out", ro.out, "FILE.png (last frame) or DIR/ (every frame)");
    c.add_option("--stats", ro.stats, "FILE.json");
    c.add_option("--threads", f.threads,
                 "auto | N: threads recording the frame's passes (1: serial; auto: up to 4)")
        ->capture_default_str();
    c.add_option("--timing", f.timing, "auto | timestamps | submit (per-pass submit+wait)")
        ->capture_default_str();
    c.add_option("--trace", ro.trace,
                 "FILE.json: Chrome trace events (CPU frontend and GPU passes per frame; "
                 "chrome://tracing, Perfetto)");
    c.add_flag("--passes", ro.printPasses, "print the per-pass timing table");
    c.add_option("--capture", f.captures,
                 "NAME[,NAME...]: write named resources of the last frame (EXR for HDR and "
                 "depth, PNG, false colour for IDs and masks); list: print the names");
    c.add_option("--capture-dir", ro.captureDir,
                 "DIR for --capture files (default: next to --out)");
}

void addSceneFlags(CLI::App& c, RenderFlags& f) {
    RenderOptions& ro = f.options;
    c.add_option("--density", f.density,
                 "auto (per mesh, from what the run's cameras can need; large meshes split into "
                 "chunks) | shadels per metre (one density, no chunks)")
        ->capture_default_str();
    c.add_option("--cache-dir", ro.cacheDir, "bake cache directory");
    c.add_option("--shadel-budget", ro.shadelBudget,
                 "decoupled: max MIP-0 shadels for the scene (lowers --density)")
        ->capture_default_str()
        ->check(finiteInRange(kShadelBudgetRange));
    c.add_option("--gi-local-volumes", f.giLocalVolumes,
                 "GI: on | off: the scene's fixed local volumes (glTF node extras "
                 "\"shadel_gi_volume\": true), read before the camera cascades")
        ->capture_default_str();
    f.instances = c.add_option("--instances", ro.instances, "builtin:many: instances, 1..1000000");
    c.add_option("--stencil-effects", f.stencilEffects,
                 "off | on | on-unbounded | fullscreen: water composite and character outline "
                 "with occlusion tint, culled by the stencil test within their instances' screen "
                 "rects (on-unbounded: full-screen triangles with the stencil test; fullscreen: "
                 "every pixel, the baseline; needs --screen-space on)")
        ->capture_default_str();
    c.add_option("--texture-budget", ro.textureBudgetMiB,
                 "MiB: stream textures into a layered cache that never exceeds this (default: "
                 "every texture resident)")
        ->check(finiteInRange(kTextureBudgetRange));
    c.add_option("--streaming", f.streaming, "layered | sparse: texture streaming residency")
        ->capture_default_str();
    c.add_option("--texture-compression", f.textureCompression,
                 "bc | none: streamed textures block-compressed (BC7, 1 byte a texel; RGBA8 with a "
                 "warning where the device cannot sample BC) or RGBA8 (4 bytes)")
        ->capture_default_str();
    c.add_option("--gallery-texture-size", ro.galleryTextureSize,
                 "builtin:textures: side of each texture (power of two, default 2048)");
}

// The command's own flags into RenderOptions (the table's are applied before).
void applyRenderFlags(RenderFlags& f) {
    RenderOptions& ro = f.options;
    ro.jitter = parseChoice<bool>("--jitter", f.jitter, {{"none", false}, {"subpixel", true}});
    ro.gpuSkinning = parseChoice<bool>("--skinning", f.skinning, {{"gpu", true}, {"cpu", false}});
    ro.timing = parseTiming(f.timing);
    ro.threads = parseThreads(f.threads);
    ro.shadelsPerMetre = parseDensity(f.density);
    ro.cameraPath = parseCameraPath(f.cameraPath);
    if (!f.cameraCut.empty()) parseCameraCut(f.cameraCut, ro.cutCamera, ro.cutFrame);
    if (f.time >= 0.0) ro.time = f.time;
    if (f.timeStep != 0.0) {
        ro.timeStep = f.timeStep;
        if (!ro.time) ro.time = 0.0;
    }
    if (!f.from.empty()) ro.cameraOverrides.from = parseVec3("--from", f.from, kCoordinateRange);
    if (!f.lookAt.empty())
        ro.cameraOverrides.lookAt = parseVec3("--look-at", f.lookAt, kCoordinateRange);
    ro.sceneGiVolumes =
        parseChoice<bool>("--gi-local-volumes", f.giLocalVolumes, {{"on", true}, {"off", false}});
    if (*f.instances && ro.instances == 0) throw InputError("--instances 0: expected 1..1000000");
    ro.stencilEffects = parseChoice<StencilEffects>("--stencil-effects", f.stencilEffects,
                                                    {{"off", StencilEffects::Off},
                                                     {"on", StencilEffects::On},
                                                     {"on-unbounded", StencilEffects::OnUnbounded},
                                                     {"fullscreen", StencilEffects::FullScreen}});
    ro.streaming = parseChoice<StreamingMode>(
        "--streaming", f.streaming,
        {{"layered", StreamingMode::Layered}, {"sparse", StreamingMode::Sparse}});
    ro.textureCompression = parseChoice<TextureCompression>(
        "--texture-compression", f.textureCompression,
        {{"bc", TextureCompression::Bc}, {"none", TextureCompression::None}});
    if (!f.captures.empty()) ro.captures = parseCaptureNames(f.captures);
}

// One line per run, and for a decoupled run what it is judged by.
void printSummary(const RenderOptions& ro, const nlohmann::json& s) {
    std::printf("%s %s %ux%u: %u frame(s), median %.2f ms, %llu px covered, %llu shader asserts, "
                "%llu validation errors%s%s\n",
                ro.scene.c_str(), s["mode"].get<std::string>().c_str(), ro.width, ro.height,
                ro.frames, s["frame_ms"]["median"].get<double>(),
                (unsigned long long)s["pixels_covered"].get<uint64_t>(),
                (unsigned long long)s["shader_asserts"].get<uint64_t>(),
                (unsigned long long)s["validation_errors"].get<uint64_t>(),
                ro.out.empty() ? "" : " -> ", ro.out.c_str());
    if (s["mode"] != "decoupled") return;
    std::string line = format("  %.2f shadels per covered pixel, %llu reconstruction misses",
                              s["shadels_per_pixel"].get<double>(),
                              (unsigned long long)s["reconstruction_misses"].get<uint64_t>());
    if (s["reuse"].get<bool>() && ro.frames > 1) {
        line += format(", %.1f%% of stored shadels carried over; shaded for",
                       100.0 * s["reuse_fraction"].get<double>());
        // Largest first (SHADEL_SHADED_*: --visualize reuse shows where).
        std::vector<std::pair<double, std::string>> reasons;
        for (const auto& [name, fraction] : s["shaded_because"].items())
            if (fraction.get<double>() > 0.0) reasons.push_back({fraction.get<double>(), name});
        std::sort(reasons.rbegin(), reasons.rend());
        for (size_t i = 0; i < reasons.size(); ++i)
            line += format("%s %s %.1f%%", i ? "," : "", reasons[i].second.c_str(),
                           100.0 * reasons[i].first);
    }
    std::printf("%s\n", line.c_str());
}

int runRenderCommand(RenderFlags& f, const GlobalFlags& g) {
    RenderOptions& ro = f.options;
    ro.allowExternalFiles = g.allowExternalFiles;
    ro.cacheLimitBytes = g.cacheLimitBytes;
    applySettingFlags(f.settings, {ro, ro.addDefaultSun});
    applyRenderFlags(f);
    GpuGuard device(g);
    RenderRun run = runRender(device.gpu, ro);
    if (run.listedCaptures) return 0;
    const nlohmann::json& s = run.stats;
    printSummary(ro, s);
    return s["shader_asserts"].get<uint64_t>() || s["validation_errors"].get<uint64_t>() ? 4 : 0;
}

} // namespace

Subcommand addRenderCommand(CLI::App& app) {
    auto flags = std::make_shared<RenderFlags>();
    CLI::App* c = app.add_subcommand("render", "render frames headless to PNG + stats JSON");
    c->add_option("--scene", flags->options.scene, "builtin:NAME | FILE.gltf | FILE.glb")
        ->capture_default_str();
    addCameraFlags(*c, *flags);
    addOutputFlags(*c, *flags);
    addSceneFlags(*c, *flags);
    addSettingFlags(*c, kRenderCommand, flags->settings);
    return {c, [flags](const GlobalFlags& g) { return runRenderCommand(*flags, g); }};
}

} // namespace shadel
