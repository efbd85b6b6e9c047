#pragma once
// The `shadel` commands as functions, so tests can run them in-process on a shared device.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake/cache_folder.h"
#include "render/camera_framing.h"
#include "render/renderer.h"
#include "render/streaming/texture_streaming.h"

namespace shadel {

// `shadel render`: the renderer's settings (the option table, app/option_table.h, sets them)
// and what the command does around the renderer.
struct RenderOptions : RenderSettings {
    std::string scene = "builtin:default";
    bool allowExternalFiles = false; // glTF URIs may leave the model's folder
    bool addDefaultSun = true;       // --sun auto|off (SceneFileOptions::addDefaultSun)
    uint32_t frames = 1;
    std::string camera;
    CameraOverrides cameraOverrides; // --from, --look-at, --fov
    std::optional<double> time;      // --time: glTF animations posed at this time (seconds)
    // --time-step: animated playback, frame i posed at time (or 0) + i * timeStep (seconds)
    std::optional<double> timeStep;
    bool gpuSkinning = true; // --skinning gpu|cpu (render/skinning)
    bool jitter = false;
    std::string out;   // FILE.png or DIR/ ; empty = no image
    std::string stats; // FILE.json ; empty = none
    std::string trace; // FILE.json: Chrome trace events of the run; empty = none
    // --timing; unset: the device's default (defaultTimingMode). Hides RenderSettings::timing,
    // which beginRender sets from it.
    std::optional<TimingMode> timing;
    // --threads: recording threads (0 = auto: defaultRecordingThreads()); beginRender sets
    // RenderSettings::recordingThreads from it.
    uint32_t threads = 0;
    float shadelsPerMetre = 0.0f; // 0 = auto: view-driven per mesh (render/view_density.h)
    // (RenderSettings::cacheDir: --cache-dir, the bake cache too; "" = the default folder.)
    // --cache-limit: least recently used bake-cache files beyond it are removed (0 = none).
    uint64_t cacheLimitBytes = 4ull << 30;
    CameraPath cameraPath = CameraPath::Static;
    // --camera-cut NAME@FRAME: from that frame on the camera path starts from the scene's
    // camera NAME instead (a cut, with what the earlier frames streamed or cached still warm).
    std::string cutCamera;
    uint32_t cutFrame = 0;
    // --gi-local-volumes on|off: the scene's fixed GI volumes (RenderSettings::giLocalVolumes).
    bool sceneGiVolumes = true;
    double shadelBudget = 64e6; // MIP-0 shadels the bake may use for the whole scene
    bool printPasses = false;
    bool progress = true;
    uint32_t instances = 0; // builtin:many (--instances); 0 = the scene's default
    // --stencil-effects on|fullscreen: water composite + character outline (render/stencil)
    StencilEffects stencilEffects = StencilEffects::Off;
    // Texture streaming (render/streaming): --texture-budget MiB (0 = none: every texture
    // resident), --streaming, --texture-compression, and builtin:textures' texture side
    // (0 = 2048).
    double textureBudgetMiB = 0.0;
    StreamingMode streaming = StreamingMode::Layered;
    TextureCompression textureCompression = TextureCompression::Bc;
    uint32_t galleryTextureSize = 0;
    float textureCpuCap = 512.0f; // side up to which CPU estimates count (0: GPU feedback only)
    // --capture NAME[,NAME...] (or {"list"}) and --capture-dir: the last frame's named
    // resources (app/capture_output.h); files go to the dir or next to --out.
    std::vector<std::string> captures;
    std::string captureDir;
};

struct RenderRun {
    std::vector<FrameResult> frames;
    nlohmann::json stats;
    bool listedCaptures = false;           // --capture list: printed, nothing rendered
    std::vector<std::string> captureFiles; // written by --capture
};

// Choice options parsed as the option table's flags (app/option_table.h); InputError naming the
// flag otherwise.
void parseSize(const std::string& text, uint32_t& width, uint32_t& height); // --size WxH
RenderMode parseMode(const std::string& text);
const char* modeName(RenderMode mode); // "forward" | "decoupled"
Visualize parseVisualize(const std::string& text);
MarkingMode parseMarking(const std::string& text);
LightCulling parseLightCulling(const std::string& text);
Spectra parseSpectra(const std::string& text);
bool parseOnOff(const char* flag, const std::string& text); // "on" / "off"
// The median of `values` (0 for none): the stats' per-frame figures.
double median(std::vector<double> values);
// --camera-cut "NAME@FRAME" -> camera name and frame (>= 1); one-line InputError otherwise.
void parseCameraCut(const std::string& text, std::string& camera, uint32_t& frame);
// "X,Y" of a pixel for `flag`; one-line InputError otherwise.
void parsePixel(const char* flag, const std::string& text, int32_t& x, int32_t& y);

// The device a run measured on, as render stats and bench JSON record it ("device", "host"):
// a software device's timings are its host CPU's, so that CPU (core/host.h) goes beside it.
void recordDevice(nlohmann::json& out, const Gpu& gpu);
// The device as the bench's headings name it: "NAME", or "NAME on CPU, N threads" for a
// software device.
std::string deviceLabel(const Gpu& gpu);

// Renders with an existing Gpu (tests share one). Writes images/stats as the options say.
RenderRun runRender(Gpu& gpu, const RenderOptions& options);
// The same in steps, so that several renders can interleave their frames (the bench): load,
// bake and build the renderer; render the next frame; write images and stats and release the
// device's memory. runRender is beginRender, renderNextFrame until renderSessionDone, then
// finishRender. A session destroyed unfinished (an error) releases what it holds.
struct RenderSession;
struct RenderSessionDeleter {
    void operator()(RenderSession* session) const;
};
using RenderSessionPtr = std::unique_ptr<RenderSession, RenderSessionDeleter>;
RenderSessionPtr beginRender(Gpu& gpu, const RenderOptions& options);
bool renderSessionDone(const RenderSession& session); // every frame rendered (or --capture list)
void renderNextFrame(RenderSession& session);
RenderRun finishRender(RenderSessionPtr session);
// Writes RGBA8 pixels as an RGB PNG, or with `coverageAlpha` as an RGBA PNG whose alpha marks
// the pixels a surface covers (renders over a solid --background); throws InputError naming the
// path when it cannot.
void writePng(const std::string& path, const std::vector<uint8_t>& rgba, uint32_t width,
              uint32_t height, bool coverageAlpha = false);
// Per-pass table on stdout.
void printPassTable(const nlohmann::json& stats);

// `shadel bench`: the settings every mode starts from (the option table sets them; each mode then
// sets its own mode, reuse and compared setting) and the comparisons to run.
struct BenchOptions : RenderSettings {
    std::string scene = "builtin:default";
    bool allowExternalFiles = false;
    bool addDefaultSun = true; // --sun auto|off
    uint32_t frames = 8;
    std::string camera;
    std::string json;
    std::optional<TimingMode> timing; // hides RenderSettings::timing (as RenderOptions)
    uint32_t threads = 0;             // --threads N (0 = auto)
    bool compareThreads = false;      // --threads compare: every mode serial and threaded
    float shadelsPerMetre = 0.0f;     // 0 = auto
    CameraPath cameraPath = CameraPath::Static;
    uint64_t cacheLimitBytes = 4ull << 30;
    // --light-culling compare: forward and decoupled rendered again with no culling, and
    // ratios.light_culling_forward|decoupled = tiled / none median frame time.
    bool compareLightCulling = false;
    // --particle-lighting-compare: forward only, particle lighting atlas vs pixel vs vertex
    // (ratios.particle_lighting_atlas_over_pixel; app/bench_command.cpp).
    bool compareParticleLighting = false;
    // --spectra compare: forward and decoupled (reuse off) also with --spectra on and single;
    // ratios.spectra_forward|spectra_decoupled = on / single median frame time (the
    // spectra against one all-features shader).
    // (Without compare, --spectra auto|off sets RenderSettings::spectra, the three modes'.)
    bool compareSpectra = false;
    // --stencil-compare: forward with --screen-space on and the stencil effects, stencil-culled
    // and full-screen; ratios.stencil_outline|stencil_water = culled / full-screen pass time.
    bool compareStencil = false;
    // --shadow-culling-compare: forward only, per-view against whole-scene shadow culling
    // (ratios.shadow_culling_frame|shadow_passes = per-view / whole-scene; app/bench_command.cpp).
    bool compareShadowCulling = false;
    // --streaming-compare: forward and decoupled with every texture resident, and streamed at
    // --texture-budget (layered; sparse where the device has it), --rounds rounds interleaved;
    // ratios.streaming_<mode>_<layered|sparse> = streamed / resident render-thread CPU time.
    bool compareStreaming = false;
    double textureBudgetMiB = 128.0; // --texture-budget (streaming compare)
    uint32_t galleryTextureSize = 0; // --gallery-texture-size (builtin:textures; 0 = 2048)
    uint32_t rounds = 3;             // --rounds (streaming compare, instance scaling)
    // The forward / decoupled / reuse comparison's rounds: 1, or --rounds when given (each round
    // runs the three modes, in alternating order; ratios are the median of the rounds').
    uint32_t modeRounds = 1;
    // --interleave auto|N|runs: the runs one comparison sets side by side (the three modes of a
    // round; spectra on and single) take turns of N frames (app/bench_command.cpp
    // renderSideBySide), or run one whole run after another (runs: 0). Auto: half the frames,
    // 1 to 4 (benchFramesPerTurn), so that every run has at least two turns.
    static constexpr uint32_t kFramesPerTurnAuto = ~0u;
    uint32_t framesPerTurn = kFramesPerTurnAuto;
    // --instance-scaling N,N,...: builtin:many at each count (--lod on), --rounds rounds
    // interleaved; cpu_frame_ms per count and ratios cpu(N) / cpu(first N) (app/bench_command.cpp).
    std::vector<uint32_t> instanceScaling;
    std::vector<RenderMode> scalingModes = {RenderMode::Forward, RenderMode::Decoupled}; // --mode
    bool scalingOcclusion = true; // --occlusion on|off (instance scaling)
    // RenderSettings::cpuScopes: --cpu-scopes (instance scaling), the frontend's steps timed.
    uint32_t instances = 0; // --instances (builtin:many), every mode; 0 = the scene's default
    std::string plot;       // --plot FILE.png: per-pass bar chart (app/bench_plot.h)
    // --environment-compare: forward and decoupled lit by builtin:sky and by none, --rounds
    // rounds; ratios.environment_forward|decoupled = sky / none median frame time
    // (app/bench_environment.cpp).
    bool compareEnvironment = false;
};
nlohmann::json runBench(Gpu& gpu, const BenchOptions& options);
nlohmann::json runEnvironmentBench(Gpu& gpu, const BenchOptions& b, RenderOptions o);
// --shadow-culling-compare (app/bench_shadow_culling.cpp).
nlohmann::json runShadowCullingBench(Gpu& gpu, const BenchOptions& b, RenderOptions o);
// A pass's median GPU time in a run's stats (0 when the run has no such pass).
double passMs(const nlohmann::json& stats, const char* name);
// "1000,10000,1000000" -> the counts for --instance-scaling, each 1..kManyMaxInstances and none
// twice; one-line InputError naming the flag and the input otherwise.
std::vector<uint32_t> parseInstanceCounts(const std::string& text);

} // namespace shadel
