// `shadel`: render, bench, bake, info. Errors: one line on stderr naming the input and the
// reason; exit 2 for bad input, 3 for a device problem, 1 for anything else.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include "app/cache_command.h"
#include "app/capture_output.h"
#include "app/cli_help.h"
#include "app/cli_validate.h"
#include "app/commands.h"
#include "app/rt_flags.h"
#include "app/viewer/viewer.h"
#include "bake/bake.h"
#include "bake/cache_eviction.h"
#include "core/error.h"
#include "core/log.h"
#include "render/debug/debug_lines.h"
#include "scene/load.h"

using namespace shadel;

namespace {

// "auto" -> 0 (view-driven), else a positive number of shadels per metre.
float parseDensity(const std::string& t) {
    if (t == "auto") return 0.0f;
    char* end = nullptr;
    double v = std::strtod(t.c_str(), &end);
    if (end == t.c_str() || *end != '\0' || !(v > 0) || !std::isfinite(v) || v > 1e9)
        throw InputError(format(
            "--density %s: expected auto or a positive number of shadels per metre", t.c_str()));
    return float(v);
}

// A whole decimal number in lo..hi, else nothing.
std::optional<uint32_t> parseCount(const std::string& t, long lo, long hi) {
    char* end = nullptr;
    long v = std::strtol(t.c_str(), &end, 10);
    if (end == t.c_str() || *end != '\0' || v < lo || v > hi) return std::nullopt;
    return uint32_t(v);
}

// --threads auto | N: threads recording a frame's passes (0 = auto).
uint32_t parseThreads(const std::string& t) {
    if (t == "auto") return 0;
    std::optional<uint32_t> n = parseCount(t, 1, 64);
    if (!n) throw InputError(format("--threads %s: expected auto or 1..64", t.c_str()));
    return *n;
}

// --interleave auto | N | runs: frames per turn of the bench's side-by-side runs (0 = whole
// runs).
uint32_t parseInterleave(const std::string& t) {
    if (t == "auto") return BenchOptions::kFramesPerTurnAuto;
    if (t == "runs") return 0;
    std::optional<uint32_t> n = parseCount(t, 1, 1000);
    if (!n)
        throw InputError(
            format("--interleave %s: expected auto, runs or 1..1000 frames", t.c_str()));
    return *n;
}

std::optional<TimingMode> parseTiming(const std::string& t) {
    if (t == "auto") return std::nullopt;
    if (t == "timestamps") return TimingMode::Timestamps;
    if (t == "submit") return TimingMode::SubmitPerPass;
    throw InputError(format("--timing %s: expected auto, timestamps or submit", t.c_str()));
}

DeviceDesc deviceDesc(const std::string& device, bool validation) {
    DeviceDesc d;
    d.selection = device;
    const char* env = std::getenv("SHADEL_VALIDATION");
    d.validation = validation || (env && std::string(env) == "1");
    return d;
}

struct GpuGuard {
    Gpu gpu;
    ~GpuGuard() { destroyGpu(gpu); }
};

} // namespace

int main(int argc, char** argv) {
    CLI::App app{"shadel: a Vulkan renderer built around generalized decoupled shading"};
    app.require_subcommand(1);
    std::string device = "auto";
    bool validation = false, verbose = false;
    app.add_option("--device", device, "auto | cpu | gpu | INDEX")->capture_default_str();
    app.add_flag("--validation", validation,
                 "enable the Khronos validation layer (or SHADEL_VALIDATION=1)");
    app.add_flag("-v,--verbose", verbose, "debug logging");
    bool allowExternalFiles = false;
    app.add_flag("--allow-external-files", allowExternalFiles,
                 "let glTF buffer/image URIs point outside the model's folder");
    std::string cacheLimit = "4G";
    app.add_option("--cache-limit", cacheLimit,
                   "bake cache size; least recently used files beyond it are removed (0 = none)")
        ->capture_default_str()
        ->check(byteSize());

    // render
    RenderOptions ro;
    std::string size = "1280x720", mode = "forward", visualize = "none", jitter = "none",
                timing = "auto";
    auto* render = app.add_subcommand("render", "render frames headless to PNG + stats JSON");
    render->add_option("--scene", ro.scene, "builtin:NAME | FILE.gltf | FILE.glb")
        ->capture_default_str();
    render->add_option("--mode", mode, "forward | decoupled")->capture_default_str();
    render->add_option("--size", size, "WIDTHxHEIGHT")->capture_default_str();
    render->add_option("--frames", ro.frames, "frames to render")->capture_default_str();
    render->add_option("--camera", ro.camera,
                       "camera name (default: the scene's first; auto: frame the scene)");
    std::string from, lookAt;
    render->add_option("--from", from, "X,Y,Z: camera position (aims at the scene's centre)")
        ->check(finiteVec3(kCoordinateRange));
    render->add_option("--look-at", lookAt, "X,Y,Z: the point the camera aims at")
        ->check(finiteVec3(kCoordinateRange));
    double timeSeconds = -1.0;
    render
        ->add_option("--time", timeSeconds,
                     "SECONDS: pose glTF animations (node TRS, morph weights, skins) at this time")
        ->check(finiteInRange(kTimeRange));
    double timeStep = 0.0;
    std::string skinning = "gpu";
    render->add_option("--skinning", skinning,
                       "gpu|cpu: skinned glTF meshes skinned by a compute pass before every view "
                       "(default) or by the importer on the CPU");
    render
        ->add_option("--time-step", timeStep,
                     "SECONDS: animated playback over --frames: frame i posed at --time (default "
                     "0) + i * SECONDS (node TRS, morph weights, skins)")
        ->check(finiteInRange(kTimeStepRange));
    render
        ->add_option("--fov", ro.cameraOverrides.fovDegrees,
                     "vertical field of view in degrees (default: the camera's)")
        ->check(finiteInRange(kFovRange));
    render
        ->add_option("--jitter", jitter, "none | subpixel: sub-pixel camera offsets between frames")
        ->capture_default_str();
    render->add_option("--ssaa", ro.ssaa, "N: NxN supersampled reference")->capture_default_str();
    render
        ->add_option("--visualize", visualize,
                     "none | marking | mips | chunks | sheet | layer:radiance | layer:material | "
                     "reuse (decoupled: carried-over chunks grey; shaded ones tinted by why: "
                     "red not reusable, green new, blue refresh, orange near a changed light, "
                     "cyan RT history, yellow view turned) | "
                     "light-count | spectra (each tile's or chunk's shading permutation) | "
                     "blockers | gi (indirect light only, with --gi lpv) | rt-ao "
                     "(ray-traced AO only, with --rt-ao on) | particle-atlas | tiles (the 8x8 "
                     "tile classes, with --screen-space on)")
        ->capture_default_str();
    std::string marking = "auto";
    render
        ->add_option("--marking", marking,
                     "decoupled: auto (visibility unless --occlusion or --screen-space needs "
                     "raster) | raster (marking + reconstruction as raster passes) | visibility "
                     "(visibility buffer, compute marking + resolve)")
        ->capture_default_str();
    render->add_option("--out", ro.out, "FILE.png (last frame) or DIR/ (every frame)");
    render->add_option("--stats", ro.stats, "FILE.json");
    std::string threads = "auto";
    render
        ->add_option("--threads", threads,
                     "auto | N: threads recording the frame's passes (1: serial; auto: up to 4)")
        ->capture_default_str();
    render->add_option("--timing", timing, "auto | timestamps | submit (per-pass submit+wait)")
        ->capture_default_str();
    render->add_option("--exposure", ro.exposure, "exposure multiplier")
        ->capture_default_str()
        ->check(finiteInRange(kExposureRange));
    std::string density = "auto", benchDensity = "auto";
    render
        ->add_option("--density", density,
                     "auto (per mesh, from what the run's cameras can need; large meshes split "
                     "into chunks) | shadels per metre (one density, no chunks)")
        ->capture_default_str();
    render->add_option("--cache-dir", ro.cacheDir, "bake cache directory");
    render->add_option("--storage", ro.shadeStorageSize, "decoupled: shade storage side in shadels")
        ->capture_default_str();
    render
        ->add_option("--shading-bias", ro.shadingBias,
                     "decoupled: fractional MIP bias (+ = fewer shadels)")
        ->capture_default_str()
        ->check(finiteInRange(kShadingBiasRange));
    render
        ->add_option("--trilinear-band", ro.trilinearBand,
                     "decoupled: LOD band blended between MIPs (1 = full trilinear); narrower on "
                     "plain rough materials the material rate shades coarser (one MIP at its "
                     "full bias)")
        ->capture_default_str()
        ->check(finiteInRange(kTrilinearBandRange));
    render
        ->add_option("--material-samples", ro.materialSamples,
                     "decoupled: cap of material evaluations per shadel (1..64; procedurals are "
                     "supersampled in proportion to their footprint)")
        ->capture_default_str();
    render
        ->add_option("--shadel-budget", ro.shadelBudget,
                     "decoupled: max MIP-0 shadels for the scene (lowers --density)")
        ->capture_default_str()
        ->check(finiteInRange(kShadelBudgetRange));
    render
        ->add_option("--sheet", ro.sheetShadels,
                     "decoupled: virtual sheet side in shadels (64k..256k)")
        ->capture_default_str();
    render
        ->add_option("--forward-below", ro.forwardBelowPixels,
                     "decoupled: objects smaller on screen (pixels) are drawn forward (0 = never)")
        ->capture_default_str()
        ->check(finiteInRange(kForwardBelowRange));
    render
        ->add_option("--allocation-counters", ro.allocationCounters,
                     "decoupled: hashed storage counters to use, 1..16 (fewer only to test "
                     "that storage is shared)")
        ->capture_default_str();
    render->add_flag("--sheet-all-mips", ro.sheetAllMips,
                     "decoupled: give every visible object rects at all MIPs, not only from the "
                     "finest it can need (for comparison)");
    std::string cameraPath = "static", capacityControl = "on";
    render
        ->add_option("--camera-path", cameraPath,
                     "static | orbit | walk: camera motion over --frames")
        ->capture_default_str();
    std::string cameraCut;
    render->add_option("--camera-cut", cameraCut,
                       "CAMERA@FRAME: from FRAME on, the camera path starts from the scene's "
                       "camera CAMERA (a cut; e.g. builtin:textures back@30)");
    render
        ->add_option("--capacity-control", capacityControl,
                     "decoupled: on | off: raise the shading bias when storage runs short")
        ->capture_default_str();
    std::string levelWindows = "on";
    render
        ->add_option("--level-windows", levelWindows,
                     "decoupled: on | off: a fine level's sheet rect holds only the part of the "
                     "level last frame's samples wanted, plus a margin (off: whole levels)")
        ->capture_default_str();
    std::string materialRate = "on";
    render
        ->add_option("--material-rate", materialRate,
                     "decoupled: on | off: shade rough materials up to one MIP coarser: plain "
                     "(lighting-only) ones, and textured ones where the view magnifies their "
                     "textures (render/shadel/material_rate.h, texture_rate.h)")
        ->capture_default_str();
    std::string reuse = "on";
    render
        ->add_option("--reuse", reuse,
                     "decoupled: on | off: carry shadels whose inputs did not change over from "
                     "last frame (preserved layers)")
        ->capture_default_str();
    render
        ->add_option("--reuse-refresh", ro.reuseRefreshPeriod,
                     "decoupled: reshade every carried-over chunk at least once per N frames")
        ->capture_default_str();
    render->add_flag("--animate-lights", ro.animateLights,
                     "move point and spot lights on small circles over the frames");
    std::string oit = "wboit";
    render
        ->add_option("--oit", oit,
                     "transparency: wboit (weighted blended OIT with additiveness) | sorted "
                     "(CPU-sorted back-to-front reference)")
        ->capture_default_str();
    render->add_option("--shuffle-draws", ro.shuffleDrawsSeed,
                       "SEED: draw the transparent instances in a random order (order "
                       "independence tests)");
    std::string particleLighting = "atlas", particles = "on";
    render
        ->add_option("--particle-lighting", particleLighting,
                     "atlas | pixel | vertex: lit particle sprites read a lightmap atlas lit "
                     "per texel at an LOD from their screen size, or are lit per pixel / vertex")
        ->capture_default_str();
    render->add_option("--particles", particles, "on | off: the scene's GPU particle emitters")
        ->capture_default_str();
    std::string particleResolution = "half";
    render
        ->add_option("--particle-resolution", particleResolution,
                     "half | full: particle sprites accumulated at half resolution in their own "
                     "WBOIT targets, combined with the surfaces' in the composite")
        ->capture_default_str();
    render
        ->add_option("--particle-atlas-size", ro.particleAtlasSize,
                     "texels per side of the particle lightmap atlas (128..8192)")
        ->capture_default_str();
    std::string lightCulling = "tiled", blockers = "on", spectra = "auto", sunShadows = "pcf",
                spotShadows = "on", lightGrid = "on";
    render
        ->add_option("--light-culling", lightCulling,
                     "tiled | none: per-tile (forward) and per-chunk (shadel) light lists")
        ->capture_default_str();
    render
        ->add_option("--light-grid", lightGrid,
                     "on | off: tiles and shadel chunks take their candidate lights from a "
                     "world-space light grid (off: each tests every light; the same lists)")
        ->capture_default_str();
    render
        ->add_option("--blockers", blockers,
                     "on | off: light blockers and portals stop the lights that list them")
        ->capture_default_str();
    render
        ->add_option("--spectra", spectra,
                     "auto | on | off | single: shading by permutations compiled with only the "
                     "features each 16x16 tile (forward) or 8x8-shadel chunk (decoupled) needs "
                     "(single: one all-features permutation; off: the raster forward pass, the "
                     "plain shadel shading; auto: on in decoupled frames with more than 64 "
                     "lights, else off)")
        ->capture_default_str();
    render
        ->add_option("--sun-shadows", sunShadows,
                     "pcf | pcss: the sun's shadow filter (pcss: variable penumbra)")
        ->capture_default_str();
    std::string decals = "on", proxyShadows = "on";
    render
        ->add_option("--proxy-shadows", proxyShadows,
                     "on | off: shadow views draw each mesh's proxy index set (positions only)")
        ->capture_default_str();
    render
        ->add_option("--decals", decals,
                     "on | off: the scene's projected box decals (base colour, normal, "
                     "roughness, ambient occlusion)")
        ->capture_default_str();
    std::string sunCascades = "1";
    render
        ->add_option("--sun-cascades", sunCascades,
                     "1..4: the sun's shadow as N cascaded maps over the view depth (1: one map "
                     "fitted to the scene)")
        ->capture_default_str();
    std::string shadowCache = "on";
    render
        ->add_option("--shadow-cache", shadowCache,
                     "on | off: keep the sun's shadow map while the sun and its casters stay put, "
                     "drawn once from every caster in its volume (off: redrawn every frame from "
                     "the casters whose shadow can reach the view)")
        ->capture_default_str();
    std::string fuseTonemap = "on";
    render
        ->add_option("--fuse-tonemap", fuseTonemap,
                     "on | off: where nothing draws into the scene colour after the opaque "
                     "shading pass (no blended materials, particles, screen-space passes, debug "
                     "lines, --ssaa 1), that pass writes the display pixels itself and the "
                     "tonemap pass does not run (off: always a separate pass)")
        ->capture_default_str();
    std::string shadowCulling = "per-view";
    render
        ->add_option("--shadow-culling", shadowCulling,
                     "per-view | whole-scene: each sun cascade and shadow-casting spot draws "
                     "its own GPU-culled casters, or all draw the sun's whole-scene list")
        ->capture_default_str();
    render
        ->add_option("--spot-shadows", spotShadows,
                     "on | off: shadow maps (one atlas) for the spots that cast shadows")
        ->capture_default_str();
    render->add_option("--trace", ro.trace,
                       "FILE.json: Chrome trace events (CPU frontend and GPU passes per frame; "
                       "chrome://tracing, Perfetto)");
    render->add_flag("--passes", ro.printPasses, "print the per-pass timing table");
    std::string gi = "off", giSnap = "on", giBlockerCells = "on", giLocalVolumes = "on";
    render
        ->add_option("--gi", gi,
                     "lpv | off: light propagation volume GI (sun + shadow-casting spot RSMs, "
                     "3 camera cascades of 32^3)")
        ->capture_default_str();
    render->add_option("--gi-iterations", ro.giIterations, "GI: propagation steps (0..64)")
        ->capture_default_str();
    render
        ->add_option("--gi-snap", giSnap,
                     "GI: on | off: snap the cascades to their cell size (off only to measure "
                     "swimming)")
        ->capture_default_str();
    render
        ->add_option("--gi-blocker-cells", giBlockerCells,
                     "GI: on | off: each tap tests only the light blockers of its 4^3 "
                     "macro-cell (off: every blocker, for comparison)")
        ->capture_default_str();
    render
        ->add_option("--gi-local-volumes", giLocalVolumes,
                     "GI: on | off: the scene's fixed local volumes (glTF node extras "
                     "\"shadel_gi_volume\": true), read before the camera cascades")
        ->capture_default_str();
    // World scale (render/culling): instance count of builtin:many, LODs, occlusion culling.
    std::string lod = "off", occlusion = "off";
    auto* instancesFlag =
        render->add_option("--instances", ro.instances, "builtin:many: instances, 1..1000000");
    render
        ->add_option("--lod", lod,
                     "on | off: pick each instance's LOD on the GPU by projected error")
        ->capture_default_str();
    render
        ->add_option("--occlusion", occlusion,
                     "on | off: two-phase hierarchical-Z occlusion culling of instances")
        ->capture_default_str();
    std::string debugLines = "none";
    render
        ->add_option("--debug-lines", debugLines,
                     "none | KIND[,KIND...]: 3-D lines drawn over the frame, emitted by shaders: "
                     "lights (ranges, cones), blockers (rectangles, portals, shadow frusta), "
                     "chunks (world boxes of the shadel chunks shaded)")
        ->capture_default_str();
    std::string debugLinesAt;
    render->add_option("--debug-lines-at", debugLinesAt,
                       "X,Y: with --debug-lines lights|blockers, only the lights that reach the "
                       "surface seen at that pixel (and their blocker frusta)");
    RtFlags rtFlags; // ray tracing (render/raytracing)
    addRayTracingFlags(*render, rtFlags);
    // Seed 004's screen-space passes and tile classification (render/screenspace, tiles).
    std::string screenSpace = "off", tileClassification = "on", distanceFields = "off",
                stencilEffects = "off";
    render
        ->add_option("--screen-space", screenSpace,
                     "on | off: thin G-buffer, sky, screen-space reflections and skin SSS")
        ->capture_default_str();
    render
        ->add_option("--tile-classification", tileClassification,
                     "on | off: run the screen-space passes only on the 8x8 tiles that need them")
        ->capture_default_str();
    render
        ->add_option("--distance-fields", distanceFields,
                     "on | off: mesh distance fields in a 3-D atlas: soft sun shadows and AO "
                     "(needs --screen-space on)")
        ->capture_default_str();
    render
        ->add_option("--df-shadow-start", ro.dfShadowStart,
                     "metres: with --distance-fields on, the sun's shadow comes from the fields "
                     "beyond this distance from the camera (0: everywhere), the shadow map nearer")
        ->capture_default_str();
    render
        ->add_option("--df-residency", ro.dfResidency,
                     "metres: with --distance-fields on, only the fields of meshes with an "
                     "instance this near the camera stay in the 3-D atlas, streamed in and out "
                     "as the camera moves (0: every field, placed at load)")
        ->capture_default_str();
    render
        ->add_option(
            "--stencil-effects", stencilEffects,
            "off | on | on-unbounded | fullscreen: water composite and character "
            "outline with occlusion tint, culled by the stencil test within their "
            "instances' screen rects (on-unbounded: full-screen triangles with the "
            "stencil test; fullscreen: every pixel, the baseline; needs --screen-space on)")
        ->capture_default_str();
    // Texture streaming (render/streaming).
    render
        ->add_option("--texture-budget", ro.textureBudgetMiB,
                     "MiB: stream textures into a layered cache that never exceeds this "
                     "(default: every texture resident)")
        ->check(finiteInRange(kTextureBudgetRange));
    std::string streaming = "layered";
    render->add_option("--streaming", streaming, "layered | sparse: texture streaming residency")
        ->capture_default_str();
    render->add_option("--gallery-texture-size", ro.galleryTextureSize,
                       "builtin:textures: side of each texture (power of two, default 2048)");
    std::string captures;
    render->add_option("--capture", captures,
                       "NAME[,NAME...]: write named resources of the last frame (EXR for HDR "
                       "and depth, PNG, false colour for IDs and masks); list: print the names");
    std::string inspect;
    render->add_option("--inspect", inspect,
                       "X,Y: print what the shading computed at that pixel (instance, triangle, "
                       "MIP, chunk, material, each light's contribution)");
    render->add_option("--capture-dir", ro.captureDir,
                       "DIR for --capture files (default: next to --out)");

    // bench
    BenchOptions bo;
    std::string benchSize = "1280x720", benchTiming = "auto";
    auto* bench =
        app.add_subcommand("bench", "render the same scene forward and decoupled; print ratios");
    bench->add_option("--scene", bo.scene, "builtin:NAME | FILE.gltf | FILE.glb")
        ->capture_default_str();
    bench->add_option("--size", benchSize, "WIDTHxHEIGHT")->capture_default_str();
    bench->add_option("--frames", bo.frames, "frames per mode")->capture_default_str();
    bench->add_option("--camera", bo.camera, "camera name");
    bench->add_option("--json", bo.json, "write the results as JSON");
    bench->add_option("--plot", bo.plot, "FILE.png: the per-pass comparison as a bar chart");
    bench->add_option("--timing", benchTiming, "auto | timestamps | submit")->capture_default_str();
    std::string benchThreads = "auto";
    bench
        ->add_option("--threads", benchThreads,
                     "auto | N: threads recording each frame's passes (1: serial), or compare: "
                     "every mode serial and threaded, CPU frame times side by side")
        ->capture_default_str();
    bench->add_option("--density", benchDensity, "auto | shadels per metre")->capture_default_str();
    bench->add_option("--cache-dir", bo.cacheDir, "bake cache directory");
    std::string benchCameraPath = "static";
    bench->add_option("--camera-path", benchCameraPath, "static | orbit | walk")
        ->capture_default_str();
    bench->add_flag("--animate-lights", bo.animateLights, "move point and spot lights");
    std::string benchLightCulling = "tiled";
    bench->add_flag("--stencil-compare", bo.compareStencil,
                    "forward with --screen-space on: the stencil-culled water composite and "
                    "character outline against their full-screen versions");
    bench->add_flag("--shadow-culling-compare", bo.compareShadowCulling,
                    "instead of the three modes: forward with --shadow-culling per-view and "
                    "whole-scene; frame and shadow-pass medians and their ratios");
    bench->add_flag("--streaming-compare", bo.compareStreaming,
                    "instead of the three modes: forward and decoupled with every texture "
                    "resident and streamed at --texture-budget (layered, sparse), --rounds "
                    "interleaved rounds; render-thread CPU time per frame and its ratios");
    bench
        ->add_option("--texture-budget", bo.textureBudgetMiB,
                     "MiB: the streamed runs' texture budget (--streaming-compare)")
        ->capture_default_str()
        ->check(finiteInRange(kTextureBudgetRange));
    bench->add_option("--gallery-texture-size", bo.galleryTextureSize,
                      "builtin:textures: side of each texture (power of two, default 2048)");
    auto* benchRoundsFlag =
        bench
            ->add_option("--rounds", bo.rounds,
                         "rounds, each running every mode once (the forward / decoupled / reuse "
                         "comparison: 1 unless given, ratios are the median of the rounds'; "
                         "--spectra compare: on and single, at least 2), residency "
                         "(--streaming-compare) or instance count (--instance-scaling)")
            ->capture_default_str();
    std::string benchInstanceScaling, benchScalingMode = "both", benchScalingOcclusion = "on";
    auto* benchInstanceScalingFlag = bench->add_option(
        "--instance-scaling", benchInstanceScaling,
        "N,N,...: instead of the three modes: builtin:many at each instance count (1..1000000) "
        "with --lod on, --rounds interleaved rounds; median cpu_frame_ms per count and its ratio "
        "to the first count's");
    auto* benchScalingModeFlag =
        bench
            ->add_option("--mode", benchScalingMode,
                         "forward | decoupled | both: the --instance-scaling render modes")
            ->capture_default_str();
    auto* benchScalingOcclusionFlag =
        bench
            ->add_option("--occlusion", benchScalingOcclusion,
                         "on | off: --instance-scaling with hierarchical-Z occlusion culling")
            ->capture_default_str();
    auto* benchCpuScopesFlag =
        bench->add_flag("--cpu-scopes", bo.cpuScopes,
                        "--instance-scaling: time the frame's CPU scopes (the decoupled coarse "
                        "allocation among them; the clock reads add to cpu_frame_ms)");
    std::string benchSunCascades = "1";
    bench->add_option("--sun-cascades", benchSunCascades, "1..4: the sun's cascaded maps")
        ->capture_default_str();
    auto* benchInstancesFlag =
        bench->add_option("--instances", bo.instances, "builtin:many: instances, 1..1000000");
    bench->add_flag("--particle-lighting-compare", bo.compareParticleLighting,
                    "instead of the three modes: forward with --particle-lighting atlas, pixel "
                    "and vertex, and the particle lighting cost of atlas over pixel");
    bench
        ->add_option("--light-culling", benchLightCulling,
                     "tiled | none | compare: compare also renders forward and decoupled "
                     "without culling and reports tiled / none frame-time ratios")
        ->capture_default_str();
    bench
        ->add_option("--shading-bias", bo.shadingBias,
                     "decoupled modes: fractional MIP bias (+ = fewer shadels)")
        ->capture_default_str()
        ->check(finiteInRange(kShadingBiasRange));
    std::string benchMaterialRate = "on";
    bench
        ->add_option(
            "--material-rate", benchMaterialRate,
            "decoupled modes: on | off: rough materials shaded up to one MIP coarser (textured "
            "ones where the view magnifies their textures)")
        ->capture_default_str();
    std::string benchShadowCache = "on";
    bench
        ->add_option("--shadow-cache", benchShadowCache,
                     "on | off: keep the sun's shadow map while the sun and its casters stay put "
                     "(off: redraw it every frame)")
        ->capture_default_str();
    std::string benchFuseTonemap = "on";
    bench
        ->add_option("--fuse-tonemap", benchFuseTonemap,
                     "every mode: on | off: the tonemap fused into the opaque shading pass where "
                     "nothing draws after it (off: always a separate pass)")
        ->capture_default_str();
    std::string benchMarking = "auto";
    bench->add_option("--marking", benchMarking, "decoupled modes: auto | raster | visibility")
        ->capture_default_str();
    std::string benchLightGrid = "on";
    bench
        ->add_option(
            "--light-grid", benchLightGrid,
            "on | off: tiles and shadel chunks take their candidate lights from the light grid")
        ->capture_default_str();
    std::string benchInterleave = "auto";
    bench
        ->add_option("--interleave", benchInterleave,
                     "auto | N | runs: the runs a ratio compares (the three modes of a round, "
                     "spectra on and single) take turns of N frames (1..1000; auto: half the "
                     "frames, 1 to 4), so that the host's drift reaches each alike, or render one "
                     "whole run after another (runs)")
        ->capture_default_str();
    std::string benchSpectra = "auto";
    bench
        ->add_option("--spectra", benchSpectra,
                     "auto | off | compare: the modes' spectra as render's --spectra (auto: on in "
                     "decoupled frames with more than 64 lights); compare also renders forward "
                     "and decoupled with --spectra on and single (--rounds rounds of "
                     "alternating order, 2 unless given) and reports on / single (the median of "
                     "the rounds' ratios) and on / off frame-time ratios (the three modes then run "
                     "with --spectra off), and on / single of the shading passes (with "
                     "spectra's classify + bin)")
        ->capture_default_str();
    bench
        ->add_option("--reuse-refresh", bo.reuseRefreshPeriod,
                     "reuse mode: reshade every carried-over chunk at least once per N frames")
        ->capture_default_str();

    // bake
    std::string bakeSceneSpec = "builtin:default", bakeCache;
    float bakeDensity = 32.0f;
    bool bakeNoCache = false;
    double bakeBudget = 64e6;
    auto* bake = app.add_subcommand("bake", "bake shadel charts and triangle-ID maps (cached)");
    bake->add_option("scene", bakeSceneSpec, "builtin:NAME | FILE.gltf | FILE.glb")
        ->capture_default_str();
    bake->add_option("--density", bakeDensity, "shadels per metre")
        ->capture_default_str()
        ->check(finiteInRange(kFixedDensityRange));
    bake->add_option("--cache-dir", bakeCache, "bake cache directory");
    bake->add_option("--shadel-budget", bakeBudget,
                     "max MIP-0 shadels for the scene (lowers --density)")
        ->capture_default_str()
        ->check(finiteInRange(kShadelBudgetRange));
    bake->add_flag("--no-cache", bakeNoCache, "bake from scratch (still writes the cache)");

    // view
    ViewOptions vo;
    std::string viewSize = "1280x720";
    auto* view = app.add_subcommand("view", "open a window: fly/orbit cameras, forward/decoupled, "
                                            "debug views, per-pass timings (Xvfb works)");
    view->add_option("--scene", vo.scene, "builtin:NAME | FILE.gltf | FILE.glb")
        ->capture_default_str();
    view->add_option("--camera", vo.camera, "camera name (default: the scene's first)");
    view->add_option("--mode", vo.mode, "forward | decoupled (switchable in the window)")
        ->capture_default_str();
    view->add_option("--marking", vo.marking, "decoupled: auto | raster | visibility")
        ->capture_default_str();
    view->add_option("--size", viewSize, "WIDTHxHEIGHT of the window")->capture_default_str();
    view->add_option("--frames", vo.frames, "quit after N frames (0: when the window closes)")
        ->capture_default_str();
    view->add_option("--screenshot", vo.screenshot,
                     "FILE.png: the window's last frame (with --frames), or on the UI's button");
    std::string viewThreads = "auto";
    view->add_option("--threads", viewThreads, "auto | N: threads recording the frame's passes")
        ->capture_default_str();
    view->add_flag("--no-ui", vo.noUi, "no ImGui panel (screenshots show only the frame)");
    view->add_option("--cache-dir", vo.cacheDir, "bake cache directory");
    view->add_option("--shader-source", vo.shaderSource,
                     "GLSL folder watched for hot reload (recompiled with glslc); empty: off")
        ->capture_default_str();

    auto* info = app.add_subcommand("info", "print the device, driver, features and limits");
    std::string cacheDirForCache;
    auto* cache = app.add_subcommand("cache", "show the bake cache's folder and size");
    cache->add_option("--cache-dir", cacheDirForCache, "bake cache directory");
    auto* cacheClean = cache->add_subcommand("clean", "remove every bake cache file");
    cacheClean->fallthrough(); // `shadel cache clean --cache-dir DIR`
    showGlobalFlagsInSubcommandHelp(app);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return exitForParseError(app, e);
    }
    ro.allowExternalFiles = bo.allowExternalFiles = allowExternalFiles;
    uint64_t cacheLimitBytes = 0;
    parseByteSize(cacheLimit, cacheLimitBytes); // validated by byteSize()
    ro.cacheLimitBytes = bo.cacheLimitBytes = cacheLimitBytes;
    if (verbose) setLogLevel(LogLevel::Debug);

    try {
        if (*info) {
            std::printf("Vulkan devices:\n%s", listPhysicalDevices().c_str());
            std::printf("bake cache: %s\n", defaultCacheDir().c_str());
            GpuGuard g;
            createGpu(g.gpu, deviceDesc(device, validation));
            std::printf("selected (--device %s):\n%s", device.c_str(),
                        describeDevice(g.gpu.device).c_str());
            return 0;
        }
        if (*cache) {
            std::string dir = cacheDirForCache.empty() ? defaultCacheDir() : cacheDirForCache;
            return runCacheCommand(dir, bool(*cacheClean), cacheLimitBytes);
        }
        if (*bake) {
            Scene scene = loadScene(bakeSceneSpec, {allowExternalFiles});
            BakeSettings bs;
            bs.cacheLimitBytes = cacheLimitBytes;
            double area = 0.0;
            bs.shadelsPerMetre = sceneShadelDensity(scene, bakeDensity, bakeBudget, area);
            if (bs.shadelsPerMetre < bakeDensity)
                SHADEL_WARN("%s: %.0f units^2 of surface: using %.3f shadels/unit to stay within "
                            "%.0fM shadels",
                            bakeSceneSpec.c_str(), area, double(bs.shadelsPerMetre),
                            bakeBudget / 1e6);
            std::string dir = bakeCache.empty() ? defaultCacheDir() : bakeCache;
            if (bakeNoCache) dir = "";
            bool tty = isatty(STDERR_FILENO);
            auto start = std::chrono::steady_clock::now();
            auto baked = bakeScene(
                scene, bs, dir.empty() ? std::string() : dir, [&](size_t done, size_t total) {
                    if (tty) {
                        int width = 40, filled = total ? int(width * done / total) : width;
                        std::fprintf(stderr, "\rbake: [%s%s] %zu/%zu meshes",
                                     std::string(filled, '#').c_str(),
                                     std::string(width - filled, '.').c_str(), done, total);
                    } else if (done == total || done % 16 == 0) {
                        std::fprintf(stderr, "bake: %zu/%zu meshes\n", done, total);
                    }
                });
            if (tty) std::fprintf(stderr, "\n");
            double seconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            std::printf("%s", bakeReport(baked, seconds).c_str());
            return 0;
        }
        if (*view) {
            parseSize(viewSize, vo.width, vo.height);
            vo.allowExternalFiles = allowExternalFiles;
            vo.threads = parseThreads(viewThreads);
            vo.cacheLimitBytes = cacheLimitBytes;
            return runViewer(vo, deviceDesc(device, validation));
        }
        GpuGuard g;
        createGpu(g.gpu, deviceDesc(device, validation));
        if (*render) {
            parseSize(size, ro.width, ro.height);
            ro.mode = parseMode(mode);
            ro.visualize = parseVisualize(visualize);
            ro.marking = parseMarking(marking);
            ro.oit = parseOit(oit);
            if (jitter != "none" && jitter != "subpixel")
                throw InputError(format("--jitter %s: expected none or subpixel", jitter.c_str()));
            ro.jitter = jitter == "subpixel";
            ro.timing = parseTiming(timing);
            ro.threads = parseThreads(threads);
            ro.shadelsPerMetre = parseDensity(density);
            ro.cameraPath = parseCameraPath(cameraPath);
            if (!cameraCut.empty()) parseCameraCut(cameraCut, ro.cutCamera, ro.cutFrame);
            if (timeSeconds >= 0.0) ro.time = timeSeconds;
            if (skinning != "gpu" && skinning != "cpu")
                throw InputError(format("--skinning %s: expected gpu or cpu", skinning.c_str()));
            ro.gpuSkinning = skinning == "gpu";
            if (timeStep != 0.0) {
                ro.timeStep = timeStep;
                if (!ro.time) ro.time = 0.0;
            }
            if (!from.empty())
                ro.cameraOverrides.from = parseVec3("--from", from, kCoordinateRange);
            if (!lookAt.empty())
                ro.cameraOverrides.lookAt = parseVec3("--look-at", lookAt, kCoordinateRange);
            if (capacityControl != "on" && capacityControl != "off")
                throw InputError(
                    format("--capacity-control %s: expected on or off", capacityControl.c_str()));
            ro.capacityControl = capacityControl == "on";
            if (levelWindows != "on" && levelWindows != "off")
                throw InputError(
                    format("--level-windows %s: expected on or off", levelWindows.c_str()));
            ro.levelWindows = levelWindows == "on";
            ro.materialRate = parseOnOff("--material-rate", materialRate);
            if (reuse != "on" && reuse != "off")
                throw InputError(format("--reuse %s: expected on or off", reuse.c_str()));
            ro.reuse = reuse == "on";
            ro.lightCulling = parseLightCulling(lightCulling);
            ro.lightBlockers = parseOnOff("--blockers", blockers);
            ro.lightGrid = parseOnOff("--light-grid", lightGrid);
            ro.particleLighting = parseParticleLighting(particleLighting);
            ro.particles = parseOnOff("--particles", particles);
            if (particleResolution != "half" && particleResolution != "full")
                throw InputError(format("--particle-resolution %s: expected half or full",
                                        particleResolution.c_str()));
            ro.particleHalfRes = particleResolution == "half";
            ro.spectra = parseSpectra(spectra);
            if (sunShadows != "pcf" && sunShadows != "pcss")
                throw InputError(
                    format("--sun-shadows %s: expected pcf or pcss", sunShadows.c_str()));
            ro.sunSoftShadows = sunShadows == "pcss";
            ro.spotShadows = parseOnOff("--spot-shadows", spotShadows);
            ro.sunCascades = parseSunCascades(sunCascades);
            ro.shadowCulling = parseShadowCulling(shadowCulling);
            ro.sunShadowCache = parseOnOff("--shadow-cache", shadowCache);
            ro.fuseTonemap = parseOnOff("--fuse-tonemap", fuseTonemap);
            ro.decals = parseOnOff("--decals", decals);
            ro.proxyShadows = parseOnOff("--proxy-shadows", proxyShadows);
            ro.gi = parseGi(gi);
            if (giSnap != "on" && giSnap != "off")
                throw InputError(format("--gi-snap %s: expected on or off", giSnap.c_str()));
            ro.giSnap = giSnap == "on";
            if (giBlockerCells != "on" && giBlockerCells != "off")
                throw InputError(
                    format("--gi-blocker-cells %s: expected on or off", giBlockerCells.c_str()));
            ro.giBlockerCells = giBlockerCells == "on";
            ro.giLocalVolumes = parseOnOff("--gi-local-volumes", giLocalVolumes);
            if (*instancesFlag && ro.instances == 0)
                throw InputError("--instances 0: expected 1..1000000");
            ro.lod = parseOnOff("--lod", lod);
            ro.occlusion = parseOnOff("--occlusion", occlusion);
            ro.debugLines = parseDebugLines(debugLines);
            if (!debugLinesAt.empty())
                parsePixel("--debug-lines-at", debugLinesAt, ro.debugLinesAtX, ro.debugLinesAtY);
            ro.rt = parseRayTracingFlags(rtFlags);
            ro.screenSpace = parseOnOff("--screen-space", screenSpace);
            ro.tileClassification = parseOnOff("--tile-classification", tileClassification);
            ro.distanceFields = parseOnOff("--distance-fields", distanceFields);
            if (stencilEffects != "off" && stencilEffects != "on" &&
                stencilEffects != "fullscreen" && stencilEffects != "on-unbounded")
                throw InputError(
                    format("--stencil-effects %s: expected off, on, on-unbounded or fullscreen",
                           stencilEffects.c_str()));
            ro.stencilEffects = stencilEffects == "on"             ? StencilEffects::On
                                : stencilEffects == "fullscreen"   ? StencilEffects::FullScreen
                                : stencilEffects == "on-unbounded" ? StencilEffects::OnUnbounded
                                                                   : StencilEffects::Off;
            if (streaming != "layered" && streaming != "sparse")
                throw InputError(
                    format("--streaming %s: expected layered or sparse", streaming.c_str()));
            ro.streaming = streaming == "sparse" ? StreamingMode::Sparse : StreamingMode::Layered;
            if (!captures.empty()) ro.captures = parseCaptureNames(captures);
            if (!inspect.empty()) parseInspect(inspect, ro.inspectX, ro.inspectY);
            RenderRun run = runRender(g.gpu, ro);
            if (run.listedCaptures) return 0;
            const auto& s = run.stats;
            std::printf(
                "%s %s %ux%u: %u frame(s), median %.2f ms, %llu px covered, %llu shader asserts, "
                "%llu validation errors%s%s\n",
                ro.scene.c_str(), s["mode"].get<std::string>().c_str(), ro.width, ro.height,
                ro.frames, s["frame_ms"]["median"].get<double>(),
                (unsigned long long)s["pixels_covered"].get<uint64_t>(),
                (unsigned long long)s["shader_asserts"].get<uint64_t>(),
                (unsigned long long)s["validation_errors"].get<uint64_t>(),
                ro.out.empty() ? "" : " -> ", ro.out.c_str());
            if (s["mode"] == "decoupled") { // what a decoupled run is judged by, at a glance
                std::string line =
                    format("  %.2f shadels per covered pixel, %llu reconstruction misses",
                           s["shadels_per_pixel"].get<double>(),
                           (unsigned long long)s["reconstruction_misses"].get<uint64_t>());
                if (s["reuse"].get<bool>() && ro.frames > 1) {
                    line += format(", %.1f%% of stored shadels carried over; shaded for",
                                   100.0 * s["reuse_fraction"].get<double>());
                    // Largest first (SHADEL_SHADED_*: --visualize reuse shows where).
                    std::vector<std::pair<double, std::string>> reasons;
                    for (const auto& [name, fraction] : s["shaded_because"].items())
                        if (fraction.get<double>() > 0.0)
                            reasons.push_back({fraction.get<double>(), name});
                    std::sort(reasons.rbegin(), reasons.rend());
                    for (size_t i = 0; i < reasons.size(); ++i)
                        line += format("%s %s %.1f%%", i ? "," : "", reasons[i].second.c_str(),
                                       100.0 * reasons[i].first);
                }
                std::printf("%s\n", line.c_str());
            }
            return s["shader_asserts"].get<uint64_t>() || s["validation_errors"].get<uint64_t>()
                       ? 4
                       : 0;
        }
        if (*bench) {
            parseSize(benchSize, bo.width, bo.height);
            bo.timing = parseTiming(benchTiming);
            bo.compareThreads = benchThreads == "compare";
            if (!bo.compareThreads) bo.threads = parseThreads(benchThreads);
            bo.shadelsPerMetre = parseDensity(benchDensity);
            bo.cameraPath = parseCameraPath(benchCameraPath);
            bo.marking = parseMarking(benchMarking);
            bo.materialRate = parseOnOff("--material-rate", benchMaterialRate);
            bo.sunShadowCache = parseOnOff("--shadow-cache", benchShadowCache);
            bo.fuseTonemap = parseOnOff("--fuse-tonemap", benchFuseTonemap);
            bo.lightGrid = parseOnOff("--light-grid", benchLightGrid);
            bo.sunCascades = parseSunCascades(benchSunCascades);
            if (bo.rounds < 1 || bo.rounds > 100)
                throw InputError(format("--rounds %u: expected 1..100", bo.rounds));
            bo.modeRounds = benchRoundsFlag->count() ? bo.rounds : 1;
            bo.framesPerTurn = parseInterleave(benchInterleave);
            if (bo.compareStreaming && !(bo.textureBudgetMiB > 0.0))
                throw InputError("--streaming-compare: needs a --texture-budget above 0 MiB");
            if (*benchInstancesFlag && bo.instances == 0)
                throw InputError("--instances 0: expected 1..1000000");
            if (*benchInstanceScalingFlag) {
                bo.instanceScaling = parseInstanceCounts(benchInstanceScaling);
                if (*benchInstancesFlag)
                    throw InputError("--instances: not with --instance-scaling (which sets the "
                                     "counts)");
                if (benchScalingMode == "both")
                    bo.scalingModes = {RenderMode::Forward, RenderMode::Decoupled};
                else if (benchScalingMode == "forward" || benchScalingMode == "decoupled")
                    bo.scalingModes = {parseMode(benchScalingMode)};
                else
                    throw InputError(format("bench --mode %s: expected forward, decoupled or both",
                                            benchScalingMode.c_str()));
                bo.scalingOcclusion = parseOnOff("--occlusion", benchScalingOcclusion);
            } else {
                for (auto [flag, name] : {std::pair{benchScalingModeFlag, "--mode"},
                                          std::pair{benchScalingOcclusionFlag, "--occlusion"},
                                          std::pair{benchCpuScopesFlag, "--cpu-scopes"}})
                    if (*flag)
                        throw InputError(format("bench %s: only with --instance-scaling (the "
                                                "other benches choose their own)",
                                                name));
            }
            bo.compareLightCulling = benchLightCulling == "compare";
            if (!bo.compareLightCulling) bo.lightCulling = parseLightCulling(benchLightCulling);
            bo.compareSpectra = benchSpectra == "compare";
            if (!bo.compareSpectra) {
                if (benchSpectra != "auto" && benchSpectra != "off")
                    throw InputError(format("bench --spectra %s: expected auto, off or compare",
                                            benchSpectra.c_str()));
                bo.spectra = parseSpectra(benchSpectra);
            }
            runBench(g.gpu, bo);
            return 0;
        }
    } catch (const InputError& e) {
        std::fprintf(stderr, "shadel: %s\n", e.what());
        return 2;
    } catch (const DeviceError& e) {
        std::fprintf(stderr, "shadel: device: %s\n", e.what());
        return 3;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "shadel: %s\n", e.what());
        return 1;
    }
    return 0;
}
