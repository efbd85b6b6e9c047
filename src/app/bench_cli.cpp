// `shadel bench`: the settings every mode starts from come from the option table
// (app/option_table.h); the flags here choose the comparison.
#include <memory>

#include "app/cli_validate.h"
#include "app/commands.h"
#include "app/option_table.h"
#include "app/subcommands.h"
#include "core/error.h"
#include "core/log.h"

namespace shadel {
namespace {

struct BenchFlags {
    BenchOptions options;
    SettingFlags settings;
    std::string timing = "auto", threads = "auto", density = "auto", cameraPath = "static",
                lightCulling = "tiled", interleave = "auto", spectra = "auto", instanceScaling,
                scalingMode = "both", scalingOcclusion = "on";
    CLI::Option *rounds = nullptr, *instanceScalingFlag = nullptr, *scalingModeFlag = nullptr,
                *scalingOcclusionFlag = nullptr;
};

// --interleave auto | N | runs: frames per turn of the bench's side-by-side runs (0 = whole
// runs).
uint32_t parseInterleave(const std::string& t) {
    if (t == "auto") return BenchOptions::kFramesPerTurnAuto;
    if (t == "runs") return 0;
    char* end = nullptr;
    long n = std::strtol(t.c_str(), &end, 10);
    if (end == t.c_str() || *end != '\0' || n < 1 || n > 1000)
        throw InputError(
            format("--interleave %s: expected auto, runs or 1..1000 frames", t.c_str()));
    return uint32_t(n);
}

void addRunFlags(CLI::App& c, BenchFlags& f) {
    BenchOptions& bo = f.options;
    c.add_option("--scene", bo.scene, "builtin:NAME | FILE.gltf | FILE.glb")->capture_default_str();
    c.add_option("--frames", bo.frames, "frames per mode")->capture_default_str();
    c.add_option("--camera", bo.camera, "camera name");
    c.add_option("--json", bo.json, "write the results as JSON");
    c.add_option("--plot", bo.plot, "FILE.png: the per-pass comparison as a bar chart");
    c.add_option("--timing", f.timing, "auto | timestamps | submit")->capture_default_str();
    c.add_option("--threads", f.threads,
                 "auto | N: threads recording each frame's passes (1: serial), or compare: every "
                 "mode serial and threaded, CPU frame times side by side")
        ->capture_default_str();
    c.add_option("--density", f.density, "auto | shadels per metre")->capture_default_str();
    c.add_option("--cache-dir", bo.cacheDir, "bake cache directory");
    c.add_option("--camera-path", f.cameraPath, "static | orbit | walk")->capture_default_str();
    c.add_option("--gallery-texture-size", bo.galleryTextureSize,
                 "builtin:textures: side of each texture (power of two, default 2048)");
    c.add_option("--instances", bo.instances, "builtin:many: instances, 1..1000000");
    f.rounds = c.add_option("--rounds", bo.rounds,
                            "rounds, each running every mode once (the forward / decoupled / "
                            "reuse comparison: 1 unless given, ratios are the median of the "
                            "rounds'; --spectra compare: on and single, at least 2), residency "
                            "(--streaming-compare) or instance count (--instance-scaling)")
                   ->capture_default_str();
    c.add_option("--interleave", f.interleave,
                 "auto | N | runs: the runs a ratio compares (the three modes of a round, spectra "
                 "on and single) take turns of N frames (1..1000; auto: half the frames, 1 to "
                 "4), so that the host's drift reaches each alike, or render one whole run after "
                 "another (runs)")
        ->capture_default_str();
}

void addComparisonFlags(CLI::App& c, BenchFlags& f) {
    BenchOptions& bo = f.options;
    c.add_flag("--stencil-compare", bo.compareStencil,
               "forward with --screen-space on: the stencil-culled water composite and character "
               "outline against their full-screen versions");
    c.add_flag("--environment-compare", bo.compareEnvironment,
               "instead of the three modes: forward and decoupled lit by builtin:sky and by "
               "--environment none, --rounds rounds; median frame times and their ratios (the "
               "cost of image-based lighting)");
    c.add_flag("--shadow-culling-compare", bo.compareShadowCulling,
               "instead of the three modes: forward with --shadow-culling per-view and "
               "whole-scene; frame and shadow-pass medians and their ratios");
    c.add_flag("--streaming-compare", bo.compareStreaming,
               "instead of the three modes: forward and decoupled with every texture resident "
               "and streamed at --texture-budget (layered, sparse), --rounds interleaved rounds; "
               "render-thread CPU time per frame and its ratios");
    c.add_option("--texture-budget", bo.textureBudgetMiB,
                 "MiB: the streamed runs' texture budget (--streaming-compare)")
        ->capture_default_str()
        ->check(finiteInRange(kTextureBudgetRange));
    f.instanceScalingFlag = c.add_option(
        "--instance-scaling", f.instanceScaling,
        "N,N,...: instead of the three modes: builtin:many at each instance count (1..1000000) "
        "with --lod on, --rounds interleaved rounds; median cpu_frame_ms per count and its ratio "
        "to the first count's");
    f.scalingModeFlag =
        c.add_option("--mode", f.scalingMode,
                     "forward | decoupled | both: the --instance-scaling render modes")
            ->capture_default_str();
    f.scalingOcclusionFlag =
        c.add_option("--occlusion", f.scalingOcclusion,
                     "on | off: --instance-scaling with hierarchical-Z occlusion culling")
            ->capture_default_str();
    c.add_flag("--cpu-scopes", bo.cpuScopes,
               "--instance-scaling: time the frame's CPU scopes (the decoupled coarse allocation "
               "among them; the clock reads add to cpu_frame_ms)");
    c.add_flag("--particle-lighting-compare", bo.compareParticleLighting,
               "instead of the three modes: forward with --particle-lighting atlas, pixel and "
               "vertex, and the particle lighting cost of atlas over pixel");
    c.add_option("--light-culling", f.lightCulling,
                 "tiled | none | compare: compare also renders forward and decoupled without "
                 "culling and reports tiled / none frame-time ratios")
        ->capture_default_str();
    c.add_option("--spectra", f.spectra,
                 "auto | off | compare: the modes' spectra as render's --spectra (auto: on in "
                 "decoupled frames with more than 64 lights); compare also renders forward and "
                 "decoupled with --spectra on and single (--rounds rounds of alternating order, 2 "
                 "unless given) and reports on / single (the median of the rounds' ratios) and "
                 "on / off frame-time ratios (the three modes then run with --spectra off), and "
                 "on / single of the shading passes (with spectra's classify + bin)")
        ->capture_default_str();
}

// --instance-scaling and the flags that only it takes.
void applyScalingFlags(BenchFlags& f) {
    BenchOptions& bo = f.options;
    if (!*f.instanceScalingFlag) {
        for (auto [flag, name] : {std::pair{f.scalingModeFlag, "--mode"},
                                  std::pair{f.scalingOcclusionFlag, "--occlusion"}})
            if (*flag)
                throw InputError(format("bench %s: only with --instance-scaling (the other "
                                        "benches choose their own)",
                                        name));
        return;
    }
    bo.instanceScaling = parseInstanceCounts(f.instanceScaling);
    bo.scalingModes = parseChoice<std::vector<RenderMode>>(
        "bench --mode", f.scalingMode,
        {{"forward", {RenderMode::Forward}},
         {"decoupled", {RenderMode::Decoupled}},
         {"both", {RenderMode::Forward, RenderMode::Decoupled}}});
    bo.scalingOcclusion =
        parseChoice<bool>("--occlusion", f.scalingOcclusion, {{"on", true}, {"off", false}});
}

int runBenchCommand(BenchFlags& f, const GlobalFlags& g) {
    BenchOptions& bo = f.options;
    bo.allowExternalFiles = g.allowExternalFiles;
    bo.cacheLimitBytes = g.cacheLimitBytes;
    applySettingFlags(f.settings, {bo, bo.addDefaultSun});
    bo.timing = parseTiming(f.timing);
    bo.compareThreads = f.threads == "compare";
    if (!bo.compareThreads) bo.threads = parseThreads(f.threads);
    bo.shadelsPerMetre = parseDensity(f.density);
    bo.cameraPath = parseCameraPath(f.cameraPath);
    bo.modeRounds = f.rounds->count() ? bo.rounds : 1;
    bo.framesPerTurn = parseInterleave(f.interleave);
    applyScalingFlags(f);
    bo.compareLightCulling = f.lightCulling == "compare";
    if (!bo.compareLightCulling) bo.lightCulling = parseLightCulling(f.lightCulling);
    bo.compareSpectra = f.spectra == "compare";
    if (!bo.compareSpectra)
        bo.spectra = parseChoice<Spectra>("bench --spectra", f.spectra,
                                          {{"auto", Spectra::Auto}, {"off", Spectra::Off}});
    validate(bo); // before the device
    GpuGuard device(g);
    runBench(device.gpu, bo);
    return 0;
}

} // namespace

Subcommand addBenchCommand(CLI::App& app) {
    auto flags = std::make_shared<BenchFlags>();
    CLI::App* c =
        app.add_subcommand("bench", "render the same scene forward and decoupled; print ratios");
    addRunFlags(*c, *flags);
    addComparisonFlags(*c, *flags);
    addSettingFlags(*c, kBenchCommand, flags->settings);
    return {c, [flags](const GlobalFlags& g) { return runBenchCommand(*flags, g); }};
}

} // namespace shadel
