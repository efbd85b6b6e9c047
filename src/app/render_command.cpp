#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <unistd.h>

#include "app/capture_output.h"
#include "app/cli_validate.h"
#include "app/commands.h"
#include "app/option_table.h"
#include "app/output_files.h"
#include "app/stats_schema.h"
#include "app/trace_export.h"
#include "bake/bake.h"
#include "bake/bake_cache.h"
#include "bake/cache_folder.h"
#include "core/error.h"
#include "core/host.h"
#include "core/log.h"
#include "core/whole_number.h"
#include "gi/gi_types.h"
#include "render/animation/scene_playback.h"
#include "render/debug/inspect.h"
#include "render/gi/lpv.h"
#include "render/particles/particles.h"
#include "render/screenspace/screen_space.h"
#include "render/shadel/decoupled.h"
#include "render/view_density.h"
#include "rhi/pipeline.h"
#include "rhi/pipeline_cache.h"
#include "scene/load.h"

namespace shadel {

namespace {
// `text` parsed as the option table's `flag` would (app/option_table.h), into defaults.
RenderSettings parsedSetting(const char* flag, const std::string& text) {
    RenderSettings s;
    bool sun = true;
    parseSetting(flag, text, {s, sun});
    return s;
}
} // namespace

void parseSize(const std::string& text, uint32_t& width, uint32_t& height) {
    RenderSettings s = parsedSetting("--size", text);
    width = s.width, height = s.height;
}

RenderMode parseMode(const std::string& text) {
    return parsedSetting("--mode", text).mode;
}

Visualize parseVisualize(const std::string& text) {
    return parsedSetting("--visualize", text).visualize;
}

LightCulling parseLightCulling(const std::string& text) {
    return parsedSetting("--light-culling", text).lightCulling;
}

Spectra parseSpectra(const std::string& text) {
    return parsedSetting("--spectra", text).spectra;
}

bool parseOnOff(const char* flag, const std::string& text) {
    return parseChoice<bool>(flag, text, {{"on", true}, {"off", false}});
}

MarkingMode parseMarking(const std::string& text) {
    return parsedSetting("--marking", text).marking;
}

void parsePixel(const char* flag, const std::string& text, int32_t& x, int32_t& y) {
    auto pixel = parseWholeNumberPair(text, ",", 16383);
    if (!pixel)
        throw InputError(format("%s %s: expected X,Y (a pixel, e.g. 40,20)", flag, text.c_str()));
    x = int32_t(pixel->first), y = int32_t(pixel->second);
}

void parseCameraCut(const std::string& text, std::string& camera, uint32_t& frame) {
    size_t at = text.rfind('@');
    std::string digits = at == std::string::npos ? "" : text.substr(at + 1);
    if (at == std::string::npos || at == 0 || digits.empty() || digits.size() > 9 ||
        digits.find_first_not_of("0123456789") != std::string::npos || std::stoul(digits) == 0)
        throw InputError(format(
            "--camera-cut %s: expected CAMERA@FRAME (a scene camera, frame >= 1)", text.c_str()));
    camera = text.substr(0, at);
    frame = uint32_t(std::stoul(digits));
}

void writePng(const std::string& path, const std::vector<uint8_t>& rgba, uint32_t width,
              uint32_t height, bool coverageAlpha) {
    std::vector<uint8_t> png =
        coverageAlpha ? encodePngRgba(rgba, width, height) : encodePngRgb(rgba, width, height);
    writeOutputFile(path, png.data(), png.size());
}

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The render thread's CPU scopes (FrameResult::cpuScopes: the frontend's steps with --trace,
// every submit always): per name, the median over frames of the frame's sum of wall clock and
// of the thread's CPU time, plus "submit (all passes)". Listed in order of first appearance.
static nlohmann::json cpuScopeStats(const std::vector<FrameResult>& frames) {
    std::vector<std::string> names;
    std::map<std::string, std::pair<std::vector<double>, std::vector<double>>> perName;
    for (const FrameResult& f : frames) {
        std::map<std::string, std::pair<double, double>> sums;
        for (const CpuScope& c : f.cpuScopes) {
            for (const std::string& name :
                 {c.name,
                  std::string(c.name.rfind("submit ", 0) == 0 ? "submit (all passes)" : "")}) {
                if (name.empty()) continue;
                auto [it, added] = sums.try_emplace(name, 0.0, 0.0);
                it->second.first += c.wallMs;
                it->second.second += c.cpuMs;
            }
        }
        for (auto& [name, sum] : sums) {
            auto [it, added] = perName.try_emplace(name);
            if (added) names.push_back(name);
            it->second.first.push_back(sum.first);
            it->second.second.push_back(sum.second);
        }
    }
    nlohmann::json out = nlohmann::json::array();
    for (const std::string& name : names) {
        auto& [wall, cpu] = perName[name];
        out.push_back({{"name", name},
                       {"wall_ms", median(wall)},
                       {"thread_cpu_ms", median(cpu)},
                       {"frames", wall.size()}});
    }
    return out;
}

const char* modeName(RenderMode m) {
    return m == RenderMode::Forward     ? "forward"
           : m == RenderMode::Decoupled ? "decoupled"
                                        : "reference";
}

void printPassTable(const nlohmann::json& stats) {
    std::printf("%-24s %10s\n", "pass", "gpu ms");
    uint32_t frames = stats.value("frames", 0u);
    for (const auto& p : stats["passes"]) {
        uint32_t ran = p.value("frames", frames);
        std::printf("%-24s %10.3f", p["name"].get<std::string>().c_str(),
                    p["gpu_ms"].get<double>());
        if (ran < frames) std::printf("  (%u of %u frames)", ran, frames);
        std::printf("\n");
    }
    std::printf("%-24s %10.3f  (median frame, wall clock)\n", "frame",
                stats["frame_ms"]["median"].get<double>());
}

// A render's state between its steps (beginRender, renderNextFrame, finishRender): what one
// call of runRender keeps, so that the bench can interleave the frames of several renders.
struct RenderSession {
    RenderSession(Gpu& g, const RenderOptions& options) : gpu(g), o(options) {}
    RenderSession(const RenderSession&) = delete;
    RenderSession& operator=(const RenderSession&) = delete;
    ~RenderSession() { release(); }
    // The renderer and the uploaded scene go back to the device (on an error too).
    void release() {
        if (rendererLive) destroyRenderer(renderer);
        rendererLive = false;
        if (sceneUploaded) destroyScene(gpu, gpuScene);
        sceneUploaded = false;
    }

    Gpu& gpu;
    const RenderOptions o;
    bool outDir = false; // --out DIR/
    bool tty = false;    // progress lines on stderr
    Scene scene;
    Camera camera;
    std::optional<Camera> cutCamera; // --camera-cut
    Aabb bounds;                     // fixes the camera path
    std::vector<BakedMesh> baked;
    GpuScene gpuScene;
    bool sceneUploaded = false; // destroyScene owed
    float density = 0.0f;
    bool autoDensity = true;
    ViewDensity viewDensity;
    double bakeSeconds = 0.0, viewDensitySeconds = 0.0;
    TextureStreamingPtr streaming;
    std::optional<ScenePlayback> playback;
    RenderSettings settings;
    Renderer renderer;
    bool rendererLive = false; // destroyRenderer owed (initRenderer was called)
    RenderRun run;
    // This render's pipelines, counted around its own steps: another render's steps may come
    // between them.
    PipelineLibraryCounters pipelines;
};

void RenderSessionDeleter::operator()(RenderSession* session) const {
    delete session;
}

namespace {
void addPipelines(PipelineLibraryCounters& sum, const PipelineLibraryCounters& more) {
    sum.created += more.created;
    sum.shared += more.shared;
    sum.createSeconds += more.createSeconds;
}

// The camera of frame i: the path, the cut, the sub-pixel jitter.
CameraView viewOfFrame(const RenderSession& session, uint32_t i) {
    const RenderOptions& o = session.o;
    // (With TAA the renderer jitters the camera itself: render/taa.)
    glm::vec2 jitter = o.jitter && !taaEnabled(o) ? subpixelJitter(i) : glm::vec2(0.0f);
    const Camera& start =
        session.cutCamera && i >= o.cutFrame ? *session.cutCamera : session.camera;
    Camera onPath = cameraOnPath(start, o.cameraPath, i, o.frames, session.bounds);
    return makeCameraView(onPath, o.width * o.ssaa, o.height * o.ssaa, jitter * float(o.ssaa));
}
} // namespace

void recordDevice(nlohmann::json& out, const Gpu& gpu) {
    out["device"] = gpu.device.name;
    HostInfo host = hostInfo();
    out["host"] = {{"cpu", host.cpu}, {"threads", host.threads}};
}

std::string deviceLabel(const Gpu& gpu) {
    if (!gpu.device.isCpu) return gpu.device.name;
    HostInfo host = hostInfo();
    return format("%s on %s, %u threads", gpu.device.name.c_str(), host.cpu.c_str(), host.threads);
}

RenderRun runRender(Gpu& gpu, const RenderOptions& o) {
    RenderSessionPtr session = beginRender(gpu, o);
    while (!renderSessionDone(*session)) renderNextFrame(*session);
    return finishRender(std::move(session));
}

bool renderSessionDone(const RenderSession& session) {
    return session.run.listedCaptures || session.run.frames.size() >= session.o.frames;
}

namespace {

// Output folders made and every output file checked: fail before loading and rendering.
void prepareOutputs(RenderSession& session) {
    const RenderOptions& o = session.o;
    bool& outDir = session.outDir;
    outDir = !o.out.empty() && o.out.back() == '/';
    if (outDir) {
        std::error_code ec;
        std::filesystem::create_directories(o.out, ec);
        if (ec)
            throw InputError(format("%s: cannot create output directory (%s)", o.out.c_str(),
                                    ec.message().c_str()));
    }
    // Fail before loading and rendering, not after.
    // (A character device such as /dev/null or /dev/stdout has no extension: it gets a PNG.)
    std::error_code deviceCheck;
    if (!o.out.empty() && !outDir && !std::filesystem::is_character_file(o.out, deviceCheck))
        if (std::string why = imageFormatProblem(o.out); !why.empty())
            throw InputError(format("--out %s: %s", o.out.c_str(), why.c_str()));
    if (!o.out.empty()) requireCreatableOutput("--out", outDir ? o.out + "frame_0000.png" : o.out);
    if (!o.stats.empty()) requireCreatableOutput("--stats", o.stats);
    if (!o.trace.empty()) requireCreatableOutput("--trace", o.trace);
    requireDistinctOutputs(
        {{"--out", outDir ? std::string() : o.out}, {"--stats", o.stats}, {"--trace", o.trace}});
    bool listCaptures = o.captures.size() == 1 && o.captures[0] == "list";
    if (!o.captures.empty() && !listCaptures && !o.captureDir.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(o.captureDir, ec);
        if (ec)
            throw InputError(format("--capture-dir %s: cannot create (%s)", o.captureDir.c_str(),
                                    ec.message().c_str()));
    }
}

// The scene, the camera (and the cut's) and the bounds that fix the camera path.
void loadRunScene(RenderSession& session) {
    const RenderOptions& o = session.o;
    BuiltinSceneOptions builtin;
    builtin.instances = o.instances;
    builtin.galleryTextureSize = o.galleryTextureSize;
    Scene& scene = session.scene;
    scene = loadScene(o.scene,
                      {.allowExternalFiles = o.allowExternalFiles,
                       .time = o.time,
                       .addDefaultSun = o.addDefaultSun},
                      builtin);
    Camera& camera = session.camera;
    camera = runCamera(scene, o.camera, o.cameraOverrides, float(o.width) / float(o.height));
    std::optional<Camera>& cutCamera = session.cutCamera;
    if (!o.cutCamera.empty()) {
        if (o.cutFrame < 1 || o.cutFrame >= o.frames)
            throw InputError(format("--camera-cut %s@%u: the cut frame must be in 1..%u (--frames "
                                    "%u)",
                                    o.cutCamera.c_str(), o.cutFrame, o.frames - 1, o.frames));
        cutCamera = runCamera(scene, o.cutCamera, {}, float(o.width) / float(o.height));
    }
    // The camera path is fixed by the loaded scene's bounds (chunking does not move it).
    Aabb& bounds = session.bounds;
    bounds = scene.worldBounds();
}

// The view-driven density (auto) and, decoupled, the bake.
void densityAndBake(RenderSession& session) {
    const RenderOptions& o = session.o;
    Scene& scene = session.scene;
    const Camera& camera = session.camera;
    const std::optional<Camera>& cutCamera = session.cutCamera;
    const Aabb& bounds = session.bounds;
    std::vector<BakedMesh>& baked = session.baked;
    float& density = session.density;
    bool& autoDensity = session.autoDensity;
    autoDensity = !(o.shadelsPerMetre > 0.0f);
    ViewDensity& viewDensity = session.viewDensity;
    double& bakeSeconds = session.bakeSeconds;
    double& viewDensitySeconds = session.viewDensitySeconds;
    if (autoDensity) {
        auto start = std::chrono::steady_clock::now();
        // Density from what this run's cameras can need, large meshes split into chunks. Both
        // modes draw the same (split) scene, so pixel coverage is identical between them.
        RunViews views =
            runViews(camera, o.cameraPath, o.frames, bounds, o.width * o.ssaa, o.height * o.ssaa);
        if (cutCamera) { // the views after the cut need their densities too
            RunViews after = runViews(*cutCamera, o.cameraPath, o.frames, bounds, o.width * o.ssaa,
                                      o.height * o.ssaa);
            views.views.insert(views.views.end(), after.views.begin(), after.views.end());
        }
        ViewDensityOptions vo;
        vo.budget = o.shadelBudget;
        // Playback rewrites each mesh's posed vertices one to one: meshes stay whole.
        vo.chunks = !o.timeStep;
        viewDensity = viewDrivenDensity(scene, views, vo);
        scene = std::move(viewDensity.scene);
        viewDensity.scene = Scene{};
        viewDensitySeconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (o.mode == RenderMode::Decoupled && viewDensity.budgetScale < 1.0)
            SHADEL_WARN("%s: the view-driven density needs %.0fM MIP-0 shadels; every density "
                        "scaled by %.3f to stay within %.0fM (--shadel-budget)",
                        o.scene.c_str(),
                        viewDensity.mip0Shadels / 1e6 /
                            (viewDensity.budgetScale * viewDensity.budgetScale),
                        viewDensity.budgetScale, o.shadelBudget / 1e6);
    }
    if (o.mode == RenderMode::Decoupled) {
        auto bakeStart = std::chrono::steady_clock::now();
        BakeSettings bs;
        bs.cacheLimitBytes = o.cacheLimitBytes;
        if (autoDensity) {
            baked = bakeScene(scene, bs, usableCacheFolder(o.cacheDir), nullptr,
                              viewDensity.meshDensity);
        } else {
            double area = 0.0;
            bs.shadelsPerMetre = sceneShadelDensity(scene, o.shadelsPerMetre, o.shadelBudget, area);
            if (bs.shadelsPerMetre < o.shadelsPerMetre)
                SHADEL_WARN("%s: %.0f units^2 of surface at %.1f shadels/unit would need %.0fM "
                            "shadels; using %.3f shadels/unit to stay within %.0fM (--density, "
                            "--shadel-budget)",
                            o.scene.c_str(), area, double(o.shadelsPerMetre),
                            area * o.shadelsPerMetre * o.shadelsPerMetre / 1e6,
                            double(bs.shadelsPerMetre), o.shadelBudget / 1e6);
            density = bs.shadelsPerMetre;
            baked = bakeScene(scene, bs, usableCacheFolder(o.cacheDir), nullptr);
        }
        bakeSeconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - bakeStart).count();
    }
}

// Texture streaming, the upload, and animated playback.
void uploadRunScene(RenderSession& session) {
    const RenderOptions& o = session.o;
    Gpu& gpu = session.gpu;
    Scene& scene = session.scene;
    GpuScene& gpuScene = session.gpuScene;
    const std::vector<BakedMesh>& baked = session.baked;
    // Texture streaming (render/streaming): with a budget, or for textures that exist only as a
    // streaming file (builtin:textures); otherwise textures load whole as before.
    TextureStreamingPtr& streaming = session.streaming;
    bool procedural = std::any_of(scene.textures.begin(), scene.textures.end(),
                                  [](const Texture& t) { return t.procedural.kind != 0; });
    if (!scene.textures.empty() && (o.textureBudgetMiB > 0.0 || procedural)) {
        TextureStreamingSettings ts;
        ts.budgetMiB = o.textureBudgetMiB;
        ts.mode = o.streaming;
        ts.compression = o.textureCompression;
        ts.cpuCap = o.textureCpuCap;
        streaming = createTextureStreaming(gpu, scene, ts, usableCacheFolder(o.cacheDir));
    }
    uploadScene(gpu, scene, gpuScene, o.mode == RenderMode::Decoupled ? &baked : nullptr,
                streaming ? &streamedTextureSlots(*streaming) : nullptr);
    session.sceneUploaded = true;
    // --time-step: the file posed again before every frame after the first (render/animation).
    std::optional<ScenePlayback>& playback = session.playback;
    if (o.timeStep)
        playback = startPlayback(o.scene,
                                 {.allowExternalFiles = o.allowExternalFiles,
                                  .time = o.time,
                                  .addDefaultSun = o.addDefaultSun},
                                 o.time.value_or(0.0), *o.timeStep, scene);
}

// The renderer's settings: the options' own, then what the run and the scene resolve.
void resolveSettings(RenderSession& session) {
    const RenderOptions& o = session.o;
    const Scene& scene = session.scene;
    Gpu& gpu = session.gpu;
    RenderSettings& settings = session.settings;
    settings = o; // the option table's settings, then what the run resolves
    // The scene colour is read back whole for --capture and EXR output: not fused there.
    settings.fuseTonemap = o.fuseTonemap && o.captures.empty() && !isExrPath(o.out);
    // The trace's finer CPU spans (stats "cpu_scopes").
    settings.cpuScopes = !o.trace.empty() || o.cpuScopes;
    // GI stops at the scene's light blockers too (and passes their portals), as direct light.
    if (o.lightBlockers && o.gi != GiMode::Off) {
        std::vector<GiBlocker> fromScene = giBlockersOf(scene);
        size_t room = GI_MAX_BLOCKERS > settings.giBlockers.size()
                          ? GI_MAX_BLOCKERS - settings.giBlockers.size()
                          : 0;
        if (fromScene.size() > room)
            SHADEL_WARN("GI: the scene has %zu light blockers; GI uses the first %zu (at most %u)",
                        fromScene.size(), room, GI_MAX_BLOCKERS);
        fromScene.resize(std::min(fromScene.size(), room));
        settings.giBlockers.insert(settings.giBlockers.end(), fromScene.begin(), fromScene.end());
    }
    if (o.sceneGiVolumes && o.gi != GiMode::Off) { // the artist's fixed volumes (render/gi)
        size_t dropped = 0;
        settings.giLocalVolumes = giLocalVolumesOf(scene, dropped);
        if (dropped)
            SHADEL_WARN("GI: the scene has %zu local volumes; GI uses the first %u",
                        scene.giVolumes.size(), GI_MAX_LOCAL_VOLUMES);
    }
    settings.timing = o.timing ? *o.timing : defaultTimingMode(gpu); // (RenderOptions::timing)
    settings.recordingThreads = o.threads ? o.threads : defaultRecordingThreads();
}

// Builds the renderer (its pipelines: seconds on a CPU device, so it says so).
void buildRenderer(RenderSession& session) {
    const RenderOptions& o = session.o;
    Gpu& gpu = session.gpu;
    const Scene& scene = session.scene;
    GpuScene& gpuScene = session.gpuScene;
    const RenderSettings& settings = session.settings;
    const TextureStreamingPtr& streaming = session.streaming;
    Renderer& renderer = session.renderer;
    const PipelineLibraryCounters pipelinesBefore = pipelineLibraryCounters(gpu);
    session.tty = isatty(STDERR_FILENO);
    // Building the renderer compiles its pipelines: seconds on a CPU device, so say so.
    bool buildingLine = o.progress && session.tty; // open until the renderer is built
    if (buildingLine) std::fprintf(stderr, "render: building the renderer's pipelines...");
    auto renderStart = std::chrono::steady_clock::now();
    try {
        session.rendererLive = true; // (destroyRenderer takes a half-built one)
        initRenderer(renderer, gpu, settings, gpuScene);
        if (o.distanceFieldLighting)
            renderer.distanceFields =
                createDistanceFields(renderer, scene, gpuScene, usableCacheFolder(o.cacheDir));
        if (o.stencilEffects != StencilEffects::Off)
            renderer.stencilEffects =
                createStencilEffects(renderer, scene, gpuScene, o.stencilEffects);
        renderer.streaming = streaming.get();
        if (o.gpuSkinning) renderer.skinning = createSkinning(renderer, scene, gpuScene);
        renderer.pointsLines = createPointsLines(renderer, scene);
        PipelineLibraryCounters p = pipelineLibraryCountersSince(gpu, pipelinesBefore);
        addPipelines(session.pipelines, p);
        double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - renderStart).count();
        SHADEL_DEBUG("renderer built in %.2f s: %llu pipelines compiled (%.2f s of compile "
                     "time), %llu shared with earlier renderers",
                     seconds, (unsigned long long)p.created, p.createSeconds,
                     (unsigned long long)p.shared);
        if (buildingLine)
            std::fprintf(stderr,
                         "\rrender: renderer built in %.1f s (%llu pipelines compiled, "
                         "%llu shared)\n",
                         seconds, (unsigned long long)p.created, (unsigned long long)p.shared);
        buildingLine = false;
    } catch (...) {
        if (buildingLine) std::fprintf(stderr, "\n"); // the error gets a line of its own
        throw;
    }
}

} // namespace

RenderSessionPtr beginRender(Gpu& gpu, const RenderOptions& options) {
    RenderSessionPtr sessionPtr(new RenderSession(gpu, options));
    RenderSession& session = *sessionPtr;
    const RenderOptions& o = session.o;
    validate(o);
    prepareOutputs(session);
    loadRunScene(session);
    densityAndBake(session);
    uploadRunScene(session);
    resolveSettings(session);
    buildRenderer(session);
    Renderer& renderer = session.renderer;
    bool listCaptures = o.captures.size() == 1 && o.captures[0] == "list";
    if (listCaptures) {
        std::printf("%s", captureListing(renderer.captures).c_str());
        session.run.listedCaptures = true;
        session.release();
        return sessionPtr;
    }
    requireCapturesExist(renderer.captures, o.captures); // before minutes of rendering
    return sessionPtr;
}

void renderNextFrame(RenderSession& session) {
    const RenderOptions& o = session.o;
    Gpu& gpu = session.gpu;
    Renderer& renderer = session.renderer;
    RenderRun& run = session.run;
    std::optional<ScenePlayback>& playback = session.playback;
    const uint32_t i = uint32_t(run.frames.size()); // this frame's index
    if (i >= o.frames || !session.rendererLive)
        throw std::logic_error("renderNextFrame: the render has no frame left");
    const PipelineLibraryCounters pipelinesBefore = pipelineLibraryCounters(gpu);
    CameraView view = viewOfFrame(session, i);
    if (session.cutCamera && i == o.cutFrame) resetTaaHistory(renderer); // (render/taa)
    if (playback && i > 0) {
        poseFrame(gpu, *playback, i, session.gpuScene, renderer.reposedInstances,
                  renderer.skinning != nullptr, &renderer.reposedFrom);
        if (renderer.skinning)
            setSkinPoses(renderer, *renderer.skinning, playback->drawn.skinPoses);
        if (playback->lastWasPrefetched) { // it ran beside the last frame (trace)
            FrameResult& last = run.frames.back();
            auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
            last.frontendWorker.push_back(
                {"scene update", ms(playback->lastImport.start - renderer.createdAt),
                 ms(playback->lastImport.end - playback->lastImport.start),
                 playback->lastImport.cpuMs});
        }
    }
    // Frontend/backend overlap: with recording threads, the next frame's scene update (its
    // pose imported from the file) runs on a worker while this frame renders, and the
    // decoupled coarse allocation's grid visit while it records, submits and waits
    // (render/shadel/coarse_visit.h; not with playback, which writes the next frame's bounds
    // only before it).
    if (renderer.settings.recordingThreads > 1 && i + 1 < o.frames) {
        if (playback) prefetchPose(*playback, i + 1);
        renderer.nextFrame = Renderer::NextFrame{viewOfFrame(session, i + 1), playback.has_value()};
    }
    // --aa-frames: a still's earlier jittered frames, into the TAA history only.
    for (uint32_t k = 1; i == 0 && k < o.aaFrames; ++k)
        renderFrame(renderer, session.gpuScene, view);
    run.frames.push_back(renderFrame(renderer, session.gpuScene, view));
    if (i > 0) // what this frame took from the worker ran beside the last one
        for (FrontendWorkerTask& t : renderer.frontendTaken)
            run.frames[i - 1].frontendWorker.push_back(t);
    addPipelines(session.pipelines, pipelineLibraryCountersSince(gpu, pipelinesBefore));
    if (o.progress && o.frames > 1 && session.tty)
        std::fprintf(stderr, "\rrender: frame %u/%u (%.1f ms)", i + 1, o.frames,
                     run.frames.back().frameMs);
    if (session.outDir)
        writePng(format("%sframe_%04u.png", o.out.c_str(), i), run.frames.back().rgba, o.width,
                 o.height, !o.backgroundEnvironment);
    if (o.progress && o.frames > 1 && session.tty && i + 1 == o.frames) std::fprintf(stderr, "\n");
}

namespace {

// Frame, CPU, recording and per-pass times: medians over the frames.
void frameTimingStats(const std::vector<FrameResult>& frames, const RenderSettings& settings,
                      nlohmann::json& s) {
    std::vector<double> frameMs;
    for (auto& f : frames) frameMs.push_back(f.frameMs);
    std::vector<double> cpuMs;
    for (auto& f : frames) cpuMs.push_back(f.cpuFrameMs);
    s["cpu_frame_ms"] = median(cpuMs); // CPU time producing a frame, GPU waits excluded
    std::vector<double> threadMs;
    for (auto& f : frames) threadMs.push_back(f.cpuThreadMs);
    s["cpu_frame_thread_ms"] = median(threadMs); // the same, as the thread's CPU clock counts it
    // Render threading (rhi/frame.h): with more than one thread the passes are recorded in
    // parallel; the wall clock of that and the CPU time each worker spent recording.
    std::vector<double> recordingMs, recordingCpuMs;
    for (auto& f : frames) {
        recordingMs.push_back(f.recordingMs);
        double cpu = 0.0;
        for (const RecordingWorkerTiming& w : f.recordingWorkers) cpu += w.cpuMs;
        recordingCpuMs.push_back(cpu);
    }
    s["recording"] = {{"threads", settings.recordingThreads},
                      {"wall_ms", median(recordingMs)},
                      {"workers_cpu_ms", median(recordingCpuMs)}};
    s["cpu_scopes"] = cpuScopeStats(frames);
    std::vector<double> streamingMs;
    for (auto& f : frames) streamingMs.push_back(f.cpuStreamingMs);
    s["cpu_streaming_thread_ms"] = median(streamingMs); // of which the texture streaming frontend
    s["frame_ms"] = {{"median", median(frameMs)},
                     {"min", *std::min_element(frameMs.begin(), frameMs.end())},
                     {"max", *std::max_element(frameMs.begin(), frameMs.end())}};
    // Per pass, the median over the frames that ran it, matched by name (and occurrence within
    // the frame): frames differ in their pass lists (spot shadow maps are drawn only when they
    // change, the first frame builds what later frames reuse), so the i-th pass of one frame
    // is not the i-th of another. Listed in order of first appearance.
    std::vector<std::pair<std::string, int>> passKeys;
    std::map<std::pair<std::string, int>, std::vector<double>> passMs, recordCpuMs;
    for (auto& f : frames) {
        std::map<std::string, int> seen;
        for (auto& pt : f.passes) {
            std::pair<std::string, int> key{pt.name, seen[pt.name]++};
            auto [it, added] = passMs.try_emplace(key);
            if (added) passKeys.push_back(key);
            it->second.push_back(pt.gpuMs);
            recordCpuMs[key].push_back(pt.recordCpuMs);
        }
    }
    nlohmann::json passes = nlohmann::json::array();
    for (auto& key : passKeys) {
        const std::vector<double>& ms = passMs[key];
        nlohmann::json p = {{"name", key.first}, {"gpu_ms", median(ms)}, {"frames", ms.size()}};
        // Threaded recording times every pass; serial recording with --trace.
        if (settings.recordingThreads > 1 || settings.cpuScopes)
            p["record_cpu_ms"] = median(recordCpuMs[key]);
        passes.push_back(p);
    }
    s["passes"] = passes;
}

// --inspect: what the shading computed at the pixel in the last frame, printed and returned.
nlohmann::json printInspectedPixel(const RenderOptions& o, const FrameResult& last) {
    nlohmann::json prints = nlohmann::json::array();
    InspectedPixel pixel = frontFragment(last.prints);
    std::printf("--inspect %d,%d (%s, last frame, the front of %u fragment(s) shaded "
                "there):\n",
                o.inspectX, o.inspectY, modeName(o.mode), pixel.fragments);
    for (const ShaderPrint& p : pixel.prints) {
        std::printf("  %s\n", p.text().c_str());
        std::vector<double> values;
        for (uint32_t i = 0; i < p.count; ++i) values.push_back(p.f(int(i)));
        prints.push_back({{"label", printLabelName(p.label)},
                          {"values", values},
                          {"shader", shaderName(p.shaderId)},
                          {"line", p.line}});
    }
    if (pixel.prints.empty()) std::printf("  nothing was shaded at this pixel (background)\n");
    return prints;
}

// The stats of the features a run may use: playback, skinning, GI, ray tracing, screen-space
// passes, distance fields, texture memory.
void featureStats(const RenderSession& session, nlohmann::json& s) {
    const Gpu& gpu = session.gpu;
    const Renderer& renderer = session.renderer;
    const GpuScene& gpuScene = session.gpuScene;
    const std::optional<ScenePlayback>& playback = session.playback;
    const TextureStreamingPtr& streaming = session.streaming;
    if (playback)
        s["animation"] = {{"time_start", playback->startTime},
                          {"time_step", playback->step},
                          {"instances_reposed", playback->instancesReposed},
                          {"meshes_reposed", playback->meshesReposed},
                          {"vertices_written", playback->verticesWritten},
                          // The next frame's import on the frontend worker, beside this frame.
                          {"frontend_prefetched", playback->prefetched},
                          {"frontend_worker_cpu_ms", playback->prefetchCpuMs},
                          {"frontend_wait_ms", playback->prefetchWaitMs}};
    s["points_lines_vertices"] =
        renderer.pointsLines ? pointsLinesVertexCount(*renderer.pointsLines) : 0u;
    s["skinning"] = {
        {"mode", renderer.skinning ? "gpu" : "cpu"},
        {"gpu_vertices", renderer.skinning ? skinnedVertexCount(*renderer.skinning) : 0u}};
    if (renderer.gi) giStats(renderer, s);
    if (renderer.rt) rayTracingStats(renderer, s);
    if (renderer.reference) referenceStats(renderer, s);
    if (renderer.screenSpace) screenSpaceStats(renderer, s);
    if (renderer.distanceFields) distanceFieldStats(*renderer.distanceFields, s);
    taaStats(renderer, s);
    if (streaming) {
        textureStreamingStats(*streaming, s);
    } else { // textures loaded whole (RGBA8 with MIPs, what the images need at least)
        uint64_t bytes = 0;
        for (TextureHandle t : gpuScene.textures)
            if (t) bytes += uint64_t(desc(gpu, t).width) * desc(gpu, t).height * 4 * 4 / 3;
        s["texture_memory_peak_bytes"] = bytes;
        s["texture_total_bytes"] = bytes;
        s["texture_bytes_per_texel"] = bytes ? 4.0 : 0.0;
    }
}

} // namespace

RenderRun finishRender(RenderSessionPtr sessionPtr) {
    RenderSession& session = *sessionPtr;
    if (session.run.listedCaptures) return std::move(session.run);
    if (!renderSessionDone(session))
        throw std::logic_error("finishRender: frames are left to render");
    Gpu& gpu = session.gpu;
    const RenderOptions& o = session.o;
    Renderer& renderer = session.renderer;
    RenderRun& run = session.run;
    const bool outDir = session.outDir;
    const Scene& scene = session.scene;
    const Camera& camera = session.camera;
    const std::optional<Camera>& cutCamera = session.cutCamera;
    const RenderSettings& settings = session.settings;
    GpuScene& gpuScene = session.gpuScene;
    const bool autoDensity = session.autoDensity;
    const ViewDensity& viewDensity = session.viewDensity;
    const std::vector<BakedMesh>& baked = session.baked;
    const float density = session.density;
    const double bakeSeconds = session.bakeSeconds;
    const double viewDensitySeconds = session.viewDensitySeconds;
    if (!o.out.empty() && !outDir) {
        if (isExrPath(o.out))
            // (reference: the accumulated mean in full float, not the half-float scene colour)
            writeHdrFrame(renderer.captures, o.ssaa, o.out,
                          renderer.reference ? "reference" : "hdr");
        else
            writePng(o.out, run.frames.back().rgba, o.width, o.height, !o.backgroundEnvironment);
    }
    if (!o.captures.empty())
        run.captureFiles = writeCaptures(renderer.captures, o.captures, o.captureDir, o.out);

    // Stats (every key, its unit and meaning: docs/stats.md; the layout: docs/stats.schema.json):
    // medians over frames.
    nlohmann::json s;
    s["schema"] = kStatsSchemaVersion;
    recordDevice(s, gpu);
    s["driver"] = gpu.device.driver;
    s["scene"] = o.scene;
    s["camera"] = camera.name;
    // Where the (first frame's) camera stood and looked: an automatic one can be reproduced with
    // --from and --look-at.
    s["camera_position"] = {camera.position.x, camera.position.y, camera.position.z};
    s["camera_forward"] = {camera.forward.x, camera.forward.y, camera.forward.z};
    if (cutCamera) s["camera_cut"] = {{"camera", cutCamera->name}, {"frame", o.cutFrame}};
    s["mode"] = modeName(o.mode);
    if (o.mode == RenderMode::Decoupled)
        s["marking"] = renderer.settings.marking == MarkingMode::Raster ? "raster" : "visibility";
    s["width"] = o.width;
    s["height"] = o.height;
    s["ssaa"] = o.ssaa;
    s["frames"] = o.frames;
    // What the run was asked for, every option of the table (app/option_table.h).
    s["settings"] = settingsJson({o, o.addDefaultSun}, kRenderCommand);
    s["timing"] = settings.timing == TimingMode::Timestamps ? "timestamps" : "submit-per-pass";
    frameTimingStats(run.frames, settings, s);
    uint64_t asserts = 0;
    for (auto& f : run.frames) asserts += f.shaderAsserts;
    s["pixels_covered"] = run.frames.back().pixelsCovered;
    s["shadels_shaded"] = 0;
    s["shadels_per_pixel"] = 0.0;
    s["chunks_allocated"] = 0;
    s["chunks_capacity"] = 0;
    s["shading_bias"] = 0.0;
    s["reconstruction_misses"] = 0;
    s["shader_asserts"] = asserts;
    s["validation_errors"] = gpu.device.validationErrors.load();
    // This run's pipelines: compiled, or found already built on the device by an earlier run.
    const PipelineLibraryCounters& pipelines = session.pipelines;
    s["pipelines"] = {{"created", pipelines.created},
                      {"shared", pipelines.shared},
                      {"create_ms", pipelines.createSeconds * 1000.0}};
    // The run's pipelines are all built: the cache file is written now (not only when the device
    // goes) so the stats say what it held and what this run added (rhi/pipeline_cache.h).
    savePipelineCache(gpu);
    const PipelineCacheState cache = pipelineCacheState(gpu);
    s["pipeline_cache"] = {{"status", cache.status},
                           {"reason", cache.reason},
                           {"file", cache.path},
                           {"loaded_bytes", cache.loadedBytes},
                           {"saved_bytes", cache.savedBytes},
                           {"save_error", cache.saveError}};
    s["instances"] = gpuScene.instanceCount;
    s["triangles"] = scene.triangleCount();
    s["lights"] = scene.lights.size();
    s["oit"] = o.oit == OitMode::Wboit ? "wboit" : "sorted";
    s["transparent_draws"] = run.frames.back().transparentDraws;
    s["transparent_draws_decoupled"] = run.frames.back().transparentDecoupledDraws;
    lightCullingStats(renderer, gpuScene, s);
    if (renderer.particles) particleStats(renderer, s);
    featureSpectraStats(renderer, s);
    spotShadowStats(renderer, s);
    sunShadowCacheStats(renderer, s);
    // Frames whose opaque shading pass wrote the display pixels (render/post/tonemap.h).
    uint32_t fusedFrames = 0;
    for (const auto& f : run.frames) fusedFrames += f.tonemapFused ? 1u : 0u;
    s["tonemap_fused_frames"] = fusedFrames;
    sunCascadeStats(renderer, s);
    decalStats(renderer, s);
    s["density_mode"] = autoDensity ? "auto" : "explicit";
    if (autoDensity)
        s["view_density"] = {{"budget_scale", viewDensity.budgetScale},
                             {"mip0_shadels_estimate", viewDensity.mip0Shadels},
                             {"meshes_split", viewDensity.meshesSplit},
                             {"chunks", viewDensity.chunksMade},
                             {"meshes_unseen", viewDensity.meshesUnseen},
                             {"min_shadels_per_metre", viewDensity.minDensityWorld},
                             {"max_shadels_per_metre", viewDensity.maxDensityWorld},
                             {"seconds", viewDensitySeconds}};
    MemoryHeapStats mem = memoryStats(gpu.memory);
    s["gpu_memory"] = {{"pool_bytes", mem.poolBytes},
                       {"used_bytes", mem.usedBytes},
                       {"pools", mem.pools},
                       {"failed_allocations", gpu.failedAllocations}};
    cullingStats(renderer, s);
    debugLinesStats(renderer, s);
    if (renderer.decoupled) {
        decoupledStats(renderer, s);
        s["shadels_per_metre"] = density; // 0: view-driven (see the density fields)
        s["bake_seconds"] = bakeSeconds;
        uint64_t mip0 = 0;
        for (const BakedMesh& b : baked) mip0 += uint64_t(b.width) * b.height;
        s["mip0_shadels"] = mip0;
        s["id_map_bytes"] = gpuScene.idMapBytes;
    }
    featureStats(session, s);
    if (o.inspectX >= 0) s["inspect"] = printInspectedPixel(o, run.frames.back());
    run.stats = s;

    // The device's memory back before the files are written (as before the steps existed).
    session.release();

    if (!o.stats.empty()) writeOutputFile(o.stats, s.dump(2) + "\n");
    if (!o.trace.empty())
        writeOutputFile(o.trace,
                        chromeTrace(run.frames, o.scene + " " + modeName(o.mode)).dump() + "\n");
    if (o.printPasses) printPassTable(s);
    return std::move(run);
}

} // namespace shadel
