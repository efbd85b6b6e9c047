#pragma once
// The renderer: owns render targets, pipelines and per-frame buffers, and renders one frame
// as a list of passes (renderFrame in renderer.cpp reads top to bottom).
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "render/camera.h"
#include "render/culling/culling.h"
#include "render/debug/capture.h"
#include "render/debug/debug_lines.h"
#include "render/decals/decals.h"
#include "render/distance_fields/distance_fields.h"
#include "render/environment/environment_state.h"
#include "render/gi/lpv.h"
#include "render/gpu_scene.h"
#include "render/lighting/feature_spectra.h"
#include "render/lighting/light_culling.h"
#include "render/lighting/shadow_atlas.h"
#include "render/lighting/spot_shadows.h"
#include "render/lighting/sun_cascades.h"
#include "render/lighting/sun_shadow_cache.h"
#include "render/points_lines/points_lines.h"
#include "render/raytracing/ray_tracing.h"
#include "render/raytracing/rt_settings.h"
#include "render/reference/reference.h"
#include "render/reference/reference_settings.h"
#include "render/scene_edits.h"
#include "render/shadel/visibility.h"
#include "render/skinning/skinning.h"
#include "render/stencil/stencil_effects.h"
#include "render/taa/taa.h"
#include "render/transmission/transmission.h"
#include "rhi/frame.h"
#include "rhi/pipeline.h"
#include "rhi/shader_messages.h"

namespace shadel {

// Forward opaque material classes: plain, textures only, other features (render/forward).
constexpr uint32_t kForwardClassCount = 3;

// Reference: an unbiased path tracer of the same scene (render/reference), the oracle of the
// other modes' light transport.
enum class RenderMode { Forward, Decoupled, Reference };
// Decoupled marking + reconstruction: raster passes over the objects, or compute passes over
// the pixels of a visibility buffer (render/shadel/visibility.h). Auto (the default) is
// visibility, the faster one, unless a feature that needs the raster path is on (--occlusion on,
// --screen-space on); initRenderer resolves it, so a renderer's settings never hold Auto.
enum class MarkingMode { Auto, Raster, Visibility };
// Transparency: weighted blended OIT, or the CPU-sorted back-to-front reference (tests).
enum class OitMode { Wboit, Sorted };
// Global illumination: none, or light propagation volumes (render/gi/lpv.h).
enum class GiMode { Off, Lpv };
enum class Visualize : uint32_t {
    None = 0,
    Marking = 1,
    Mips = 2,
    Chunks = 3,
    Sheet = 4,
    LayerMaterial = 5, // --visualize layer:material (the shade storage's material layer)
    LightCount = VISUALIZE_LIGHT_COUNT, // lights per tile (forward) or chunk (shadel)
    Blockers = VISUALIZE_BLOCKERS,      // tiles / chunks with per-pixel blocker checks
    Gi = 6,                             // --visualize gi: the LPV's indirect light only
    RtAo = VISUALIZE_RT_AO,             // --visualize rt-ao: the ray-traced AO only (--rt-ao on)
    ParticleAtlas = 24,                 // --visualize particle-atlas (render/particles)
    Tiles = VISUALIZE_TILES,            // --visualize tiles: 8x8 tile classes (render/tiles)
    Spectra = VISUALIZE_SPECTRA,        // each tile's shading mode (--spectra on|single)
    Reuse = VISUALIZE_REUSE,            // decoupled: carried-over chunks grey, shaded by reason
};
// --tonemap: the display curve after exposure (shaders/common/tone_curve.glsl); the names are
// those of the glTF Sample Viewer's tone mappers, with the same formulas.
enum class Tonemap : uint32_t { AcesNarkowicz = 0, AcesHill = 1, KhrPbrNeutral = 2, Linear = 3 };

// --particle-lighting: lit particle sprites read the atlas, or are lit per pixel / per vertex.
enum class ParticleLighting : uint32_t { Atlas = 0, Pixel = 1, Vertex = 2 };

// --light-culling: per-tile (forward) and per-chunk (shadel) light lists, or every light for
// every pixel / shadel.
enum class LightCulling { None, Tiled };

// --shadow-culling: each sun cascade and shadow-casting spot draws its own culled casters, or
// every one of them draws the sun's whole-scene list (render/culling/culling.h).
enum class ShadowCulling { PerView, WholeScene };

// --aa: temporal anti-aliasing (render/taa) or none. Auto: each command's default (none for
// `render` and `bench`, TAA for `view`); the renderer treats it as none.
enum class AntiAliasing { Auto, None, Taa };

struct RenderSettings {
    uint32_t width = 1280, height = 720;
    uint32_t ssaa = 1; // N x N supersampling (forward reference)
    AntiAliasing aa = AntiAliasing::Auto;
    float taaSharpen = 0.0f; // --taa-sharpen: unsharp mask over the TAA output (0: off)
    // --aa-frames: a still (one frame, --camera-path static) renders this many jittered frames
    // into the TAA history and outputs the last (render/taa).
    uint32_t aaFrames = 1;
    RenderMode mode = RenderMode::Forward;
    // Decoupled only. Visibility is the default (Auto): on lavapipe the visibility prepass,
    // compute marking and compute resolve together cost less than the depth prepass, raster
    // marking and raster reconstruction (docs/decoupled/README.md has the figures).
    MarkingMode marking = MarkingMode::Auto;
    Visualize visualize = Visualize::None;
    float exposure = 1.0f; // linear multiplier; the CLI takes --exposure in EV (2^EV)
    Tonemap tonemap = Tonemap::AcesNarkowicz;
    // Image-based lighting (render/environment): "builtin:sky" (a physically based sky lit by
    // the scene's sun), "none", or an equirectangular .hdr / .exr file. Scenes whose lighting
    // is authored as a sky and ambient colour (night scenes, closed rooms) get their
    // hemisphere as an environment unless one is given (Scene::environment).
    std::string environment = "builtin:sky";
    bool environmentGiven = false; // --environment was on the command line
    float environmentIntensity = 1.0f;
    float environmentRotationDegrees = 0.0f; // about +Y
    float environmentSpinDegrees = 0.0f;     // added to the rotation every frame (a turntable)
    // --background: the environment behind the scene, or a solid sRGB colour (alpha still marks
    // coverage in PNG and EXR output).
    bool backgroundEnvironment = true;
    glm::vec3 backgroundColor{0.0f}; // sRGB, when !backgroundEnvironment
    bool shadows = true;             // --shadows off: no shadow maps (sun, spots, cascades)
    std::string cacheDir; // prefiltered environments are cached here ("": the default cache)
    uint32_t shadowMapSize = 2048;
    TimingMode timing = TimingMode::SubmitPerPass;
    // --threads: threads recording the frame's passes (1 = serial, in declaration order;
    // rhi/frame.h). The images are the same for any count.
    uint32_t recordingThreads = 1;
    uint32_t shadeStorageSize = 4096; // decoupled: physical shade storage, shadels per side
    uint32_t sheetShadels = 65536;    // decoupled: virtual sheet, shadels per side
    float shadingBias = 0.0f; // decoupled: base MIP bias (the capacity controller adds to it)
    // decoupled: LOD band blended between MIPs (1 = full trilinear). 0.5 ("brilinear"): only
    // the middle half of each LOD interval reads two MIPs. At 1280x720 it shades 24% fewer
    // chunks on builtin:default for -0.3 dB against the supersampled forward render, and 22% /
    // 12% fewer on builtin:many / 2CylinderEngine at the same PSNR (to 0.01 dB). Objects the
    // material rate shades coarser blend over a narrower band, one level at its full bias
    // (shadelLevels in shaders/shadel/shadel.glsl).
    float trilinearBand = 0.5f;
    // decoupled: cap of material evaluations per shadel above MIP 0 (procedurals are
    // supersampled in proportion to their footprint, shaders/shadel/prefilter.glsl)
    uint32_t materialSamples = 16;
    float forwardBelowPixels = 8; // decoupled: objects smaller on screen drawn forward (0 = never)
    uint32_t allocationCounters = SHADEL_COUNTERS; // decoupled: hashed counters used (tests)
    bool sheetAllMips = false; // decoupled: rects at every MIP (the old policy, for comparison)
    bool levelWindows = true;  // decoupled: fine levels' rects hold only what the view wanted
    bool materialRate = true;  // decoupled: rough materials shaded coarser (shadel/material_rate.h)
    bool capacityControl = true;      // decoupled: steer the shading bias from storage use
    bool reuse = true;                // decoupled: carry unchanged shadels over from last frame
    uint32_t reuseRefreshPeriod = 16; // decoupled: reshade every carried chunk this often
    // --inspect X,Y: the output pixel whose shading is printed (shaders/debug/inspect.glsl).
    int32_t inspectX = -1, inspectY = -1;
    bool animateLights = false;   // point and spot lights move on small circles
    OitMode oit = OitMode::Wboit; // transparency: render/oit
    bool shuffleDraws = false;    // --shuffle-draws SEED: transparent draws in a random order
    uint64_t shuffleSeed = 0;
    LightCulling lightCulling = LightCulling::Tiled;
    bool lightBlockers =
        true;                // --blockers: light blockers and portals stop the lights listing them
    bool lightGrid = true;   // --light-grid: tiles and chunks take candidates from the light grid
    GiMode gi = GiMode::Off; // --gi (off by default: see render/gi/lpv.h for its cost)
    uint32_t giIterations = 8;         // --gi-iterations: LPV propagation steps
    bool giBlockerCells = true;        // GI taps test only their 4^3 macro-cell's blockers
    bool giSnap = true;                // --gi-snap off: cascades slide with the camera (debug)
    float giIntensity = 1.0f;          // scale of the indirect term
    std::vector<GiBlocker> giBlockers; // GI light blockers (axial occlusion in propagation)
    std::vector<GiLocalVolume> giLocalVolumes; // fixed GI volumes (--gi-local-volumes on)
    bool lod = false;            // GPU LOD selection by projected error (render/culling)
    float lodErrorPixels = 0.5f; // the coarsest LOD whose error projects below this is drawn
    bool occlusion = false;      // two-phase hierarchical-Z occlusion culling (render/culling)
    uint32_t debugLines =
        0; // --debug-lines: DEBUG_LINES_* kinds drawn (render/debug/debug_lines.h)
    uint32_t debugLineCapacity = 256 * 1024; // segments the line buffer holds (8 MiB)
    // --debug-lines-at X,Y: light lines only for the lights reaching the surface at that pixel
    // of the output image (-1: every light in view).
    int32_t debugLinesAtX = -1, debugLinesAtY = -1;
    RtSettings rt;               // --rt-*: ray-traced shadows, AO, GI (render/raytracing)
    ReferenceSettings reference; // --mode reference: --spp, --max-bounces, --seed
    bool particles = true;       // the scene's GPU particle emitters (render/particles)
    ParticleLighting particleLighting = ParticleLighting::Atlas;
    uint32_t particleAtlasSize = 1024; // texels per side of the particle lightmap atlas
    // Sprites accumulated at half resolution in their own WBOIT targets, combined with the
    // full-resolution surfaces' in the composite (low-resolution particles).
    bool particleHalfRes = true;
    // Seed 004's screen-space passes (render/screenspace: thin G-buffer, sky, SSR, SSS) and
    // whether they run per classified 8x8 tile (render/tiles) or over every tile.
    bool screenSpace = false;
    bool tileClassification = true;
    // --distance-fields on: forward and shadel shading compiled with the DF far shadows + AO
    // (render/distance_fields); the sun's shadow map gives way to the fields beyond this many
    // metres from the camera (0: everywhere).
    bool distanceFieldLighting = false;
    float dfShadowStart = 40.0f;
    // Metres: only the fields of meshes with an instance this near the camera are in the atlas
    // (streamed in and out as the camera moves); 0: every field, placed at load.
    float dfResidencyDistance = 0.0f;
    Spectra spectra = Spectra::Auto; // per-tile / per-chunk shading permutations (render/lighting)
    bool sunSoftShadows = false;     // --sun-shadows pcss: variable penumbra (render/lighting)
    bool spotShadows = true;         // --spot-shadows: shadow maps of shadow-casting spots
    uint32_t sunCascades = 1;        // --sun-cascades: 1 = one map fitted to the scene
    bool proxyShadows =
        true;           // --proxy-shadows: shadow views draw proxy index sets (render/culling)
    bool decals = true; // --decals: the scene's projected box decals (render/decals)
    ShadowCulling shadowCulling = ShadowCulling::PerView; // cascades' and spots' caster lists
    bool sunShadowCache = true; // --shadow-cache: keep the sun's map while nothing in it changes
    // --fuse-tonemap: where nothing draws into the scene colour after the opaque shading pass,
    // that pass writes display pixels itself and the tonemap pass does not run
    // (render/post/tonemap.h). Off where the scene colour is read back (--capture, EXR output).
    bool fuseTonemap = true;
    // --trace: time the frame's CPU scopes (FrameResult::cpuScopes) and each pass's recording.
    // Off by default: reading a thread's CPU clock costs ~0.7 us, which would add to cpuFrameMs.
    bool cpuScopes = false;
};

// A piece of a frame's frontend that ran ahead on the frontend worker (trace: its own track).
struct FrontendWorkerTask {
    const char* name = "";
    double startMs = 0.0; // since the renderer was created
    double wallMs = 0.0;
    double cpuMs = 0.0; // the worker thread's CPU time
};

struct FrameResult {
    std::vector<uint8_t> rgba; // width x height RGBA8; alpha: covered share (0 or 255 at --ssaa 1)
    uint64_t pixelsCovered = 0;
    std::vector<PassTiming> passes;
    bool tonemapFused = false; // the opaque shading pass wrote the display pixels (render/post)
    double frameMs = 0.0;
    double cpuFrameMs = 0.0;   // CPU time to produce the frame (prepare + record), no GPU wait
    double cpuPrepareMs = 0.0; // of which the CPU frontend: constants, decoupled coarse allocation
    // CPU time the rendering thread consumed in renderFrame (CLOCK_THREAD_CPUTIME_ID): not
    // inflated when other processes take the cores, as the wall-clock cpuFrameMs is.
    double cpuThreadMs = 0.0;
    // Of which the texture streaming frontend (prepare, recording its copies, finish): the
    // render thread's share of streaming, the rest runs on its worker (render/streaming).
    double cpuStreamingMs = 0.0;
    double startMs = 0.0; // since the renderer was created (trace export)
    // The next frame's frontend work that ran on the frontend worker beside this frame's backend
    // (with recording threads: the pose import of animated playback, render/animation
    // prefetchPose; the decoupled coarse visit, render/shadel/coarse_visit.h).
    std::vector<FrontendWorkerTask> frontendWorker;
    uint32_t shaderAsserts = 0;
    std::vector<ShaderPrint> prints;        // shader print records of this frame (--inspect)
    uint32_t transparentDraws = 0;          // blended instances drawn (render/oit)
    uint32_t transparentDecoupledDraws = 0; // ... of which shaded in shadel space
    // Threaded frames: the wall clock of the parallel recording and what each worker did.
    double recordingMs = 0.0;
    std::vector<RecordingWorkerTiming> recordingWorkers;
    // With RenderSettings::cpuScopes: the render thread's named CPU scopes (frontend steps,
    // recording, submits, finish), from startMs; submits are there in every case.
    std::vector<CpuScope> cpuScopes;
};

struct DecoupledState; // render/shadel/decoupled.h
struct DecoupledStateDeleter {
    void operator()(DecoupledState* state) const; // defined with the state
};
using DecoupledStatePtr = std::unique_ptr<DecoupledState, DecoupledStateDeleter>;
struct OitState;         // render/oit/oit.h
struct TextureStreaming; // render/streaming/texture_streaming.h
struct OitStateDeleter {
    void operator()(OitState* state) const;
};
using OitStatePtr = std::unique_ptr<OitState, OitStateDeleter>;
struct ParticleState; // render/particles/particles.h
struct ParticleStateDeleter {
    void operator()(ParticleState* state) const;
};
using ParticleStatePtr = std::unique_ptr<ParticleState, ParticleStateDeleter>;

struct ScreenSpaceState; // render/screenspace/screen_space.h
struct ScreenSpaceStateDeleter {
    void operator()(ScreenSpaceState* state) const;
};
using ScreenSpaceStatePtr = std::unique_ptr<ScreenSpaceState, ScreenSpaceStateDeleter>;

struct Renderer {
    Gpu* gpu = nullptr;
    RenderSettings settings;
    // Targets at the internal resolution (width*ssaa x height*ssaa).
    uint32_t internalWidth = 0, internalHeight = 0;
    TextureHandle hdr, depth;
    RenderTargetView hdrTarget;
    TextureReadView hdrRead;
    DepthTargetView depthTarget;
    TextureReadView depthRead;
    ShadowAtlas sunShadow; // the sun's whole-scene map (--sun-cascades: beyond the last slice)
    // Per-frame data.
    BufferHandle frameConstants; // host-visible gpu::FrameConstants
    BufferHandle draws;          // DrawIndexedCommand[DRAW_CAMERA_SLOTS * maxDraws], camera view
    BufferHandle shadowDraws;    // DrawIndexedCommand[DRAW_LIST_COUNT * maxDraws], the sun's
    BufferHandle drawCounts;     // uint[DRAW_CAMERA_SLOTS] camera, then uint[DRAW_LIST_COUNT] sun
    BufferHandle pixels;         // readback RGBA8
    uint32_t maxDraws = 0;
    BufferHandle sceneIndices;           // the unified index buffer of the scene being drawn
    BufferHandle sceneVisibilityIndices; // ... and the visibility prepass's (GpuScene)
    glm::vec3 skyColor{0.5f};
    // This frame's tonemap is fused into its opaque shading pass (render/post/tonemap.h): set
    // before the passes are declared.
    bool tonemapFused = false;
    // Forward with --fuse-tonemap: the display target forward shading writes when fused (RGBA8,
    // sRGB-encoded values, alpha = coverage), copied into `pixels`.
    TextureHandle display;
    RenderTargetView displayTarget;
    Pipeline instanceCull, depthPrepass, tonemap;
    // The environment behind the surfaces in the colour passes (render/background), into the
    // scene colour or the fused display target.
    Pipeline background, backgroundDisplay;
    // Forward shading of opaque surfaces, one pipeline per material class (render/forward):
    // plain materials (DRAW_LIST_OPAQUE, material features compiled out), textures only
    // (DRAW_LIST_OPAQUE_TEXTURED), any other feature (DRAW_LIST_OPAQUE_FEATURED, all of them).
    std::array<Pipeline, kForwardClassCount> forwardOpaque;
    std::array<Pipeline, kForwardClassCount> forwardDisplay; // the same into `display` (fused)
    // The scene has alpha-masked materials: the depth-only passes (prepass, shadow maps) and the
    // visibility prepass run their alpha test. Without them they are depth-only / have the test
    // compiled out, so the depth test runs before any fragment shading (early Z).
    bool alphaMasked = true;
    // The raster forward pass shades a tile's lights that read no texture in a loop of their own
    // (forwardSplitsTileLights, render/lighting/light_culling.h): chosen once, for its pipeline.
    bool forwardSplitsTileLights = false;
    ShaderMessageChannel messages;
    FrameRecorder recorder;
    DecoupledStatePtr decoupled;
    // Live lights (--animate-lights, or edited: render/scene_edits.h): this frame's lights (kept
    // as the next frame's "last"), and the volumes (xyz, radius) of the lights that changed
    // since the last frame (what the decoupled path must reshade).
    BufferHandle liveLights; // host-visible gpu::GpuLight[], once lights animate or are edited
    std::vector<gpu::GpuLight> lightsLastFrame;
    std::vector<glm::vec4> changedLightVolumes;
    uint64_t framesRendered = 0;
    VisibilityStatePtr visibility;         // decoupled with --marking visibility
    OitStatePtr oit;                       // scenes with blended materials (render/oit)
    ParticleStatePtr particles;            // scenes with particle emitters (render/particles)
    LightCullingStatePtr lightCulling;     // light lists (render/lighting/light_culling.h)
    GiStatePtr gi;                         // --gi lpv
    DebugLinesStatePtr debugLines;         // --debug-lines (render/debug/debug_lines.h)
    CullingStatePtr culling;               // LODs, occlusion, per-view counts (render/culling)
    RayTracingStatePtr rt;                 // BLASes, TLAS, traced terms (--rt-*, render/raytracing)
    ReferenceStatePtr reference;           // --mode reference: the path tracer (render/reference)
    CaptureRegistry captures;              // --capture: named resources of the frame (render/debug)
    ScreenSpaceStatePtr screenSpace;       // --screen-space on (render/screenspace, render/tiles)
    DistanceFieldStatePtr distanceFields;  // --distance-fields on (render/distance_fields)
    StencilEffectsStatePtr stencilEffects; // --stencil-effects on|fullscreen (render/stencil)
    PointsLinesStatePtr pointsLines;       // glTF points and lines, forward (render/points_lines)
    SkinningStatePtr skinning;             // skinned meshes skinned on the GPU (render/skinning)
    // Texture streaming (render/streaming), owned by the caller; null: textures loaded whole.
    TextureStreaming* streaming = nullptr;
    // Per material: what it shades with changed this frame (streaming changed a texture of it,
    // or it was edited); the decoupled path reshades its objects.
    std::vector<uint8_t> changedMaterials;
    SceneEdits edits; // the viewer's light, sun and material edits (render/scene_edits.h)
    EnvironmentState environment; // image-based lighting and the background (render/environment)
    // The environment's intensity and rotation the last frame shaded with: a change relights
    // every surface (the decoupled path reshades what it carried over).
    glm::vec2 environmentViewLastFrame{-1.0f};
    // Per instance: animated playback (render/animation) moved or deformed it before this frame;
    // empty without playback. Decoupled reuse reshades these; spot shadow maps are redrawn.
    std::vector<uint8_t> reposedInstances;
    std::vector<Aabb> reposedFrom;  // per instance: its world bounds before the playback moved it
    SpectraStatePtr spectra;        // --spectra on|single (render/lighting/feature_spectra.h)
    SpotShadowStatePtr spotShadows; // shadow-casting spots (render/lighting/spot_shadows.h)
    SunCascadeStatePtr sunCascades; // --sun-cascades 2..4 (render/lighting/sun_cascades.h)
    SunShadowCache sunShadowCache;  // the sun's map kept across frames (render/lighting)
    bool shadowCastersChanged = false; // this frame: what the kept shadow maps show changed
    DecalStatePtr decals;              // --decals on, scenes with decals (render/decals/decals.h)
    std::chrono::steady_clock::time_point createdAt = std::chrono::steady_clock::now();
    // This frame's CPU scopes so far (RenderSettings::cpuScopes) and their origin.
    std::vector<CpuScope> cpuScopes;
    std::chrono::steady_clock::time_point frameCpuStart;
    // This frame's frontend work that ran ahead on the frontend worker (the decoupled coarse
    // visit): the caller files it under the frame it ran beside (FrameResult::frontendWorker).
    std::vector<FrontendWorkerTask> frontendTaken;
    // Frontend/backend overlap: set by a caller that renders a known sequence with
    // recording threads, for one renderFrame. Once this frame's frontend is done, the next
    // frame's decoupled grid visit (render/shadel/coarse_visit.h) runs on the frontend worker
    // while this frame records, submits and waits. `sceneMoves`: animated playback writes the
    // next frame's bounds only before it, so its visit is not prefetched (counted).
    struct NextFrame {
        CameraView camera;
        bool sceneMoves = false;
    };
    std::optional<NextFrame> nextFrame;
    TransmissionStatePtr transmission; // scenes with transmissive materials (render/transmission)
    TaaStatePtr taa;                   // --aa taa (render/taa)
};

// Times the enclosing block as the CPU scope `name` of this frame (nothing unless
// RenderSettings::cpuScopes).
inline CpuScopeTimer cpuScope(Renderer& r, const char* name) {
    return CpuScopeTimer(r.settings.cpuScopes ? &r.cpuScopes : nullptr, name, r.frameCpuStart);
}

void initRenderer(Renderer& renderer, Gpu& gpu, const RenderSettings& settings,
                  const GpuScene& scene);
void destroyRenderer(Renderer& renderer);
FrameResult renderFrame(Renderer& renderer, const GpuScene& scene, const CameraView& camera);

} // namespace shadel
