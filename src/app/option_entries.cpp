// The table of app/option_table.h: every option of render, bench and view that sets a
// RenderSettings member (or the scene file's default sun), in --help order.
#include "app/option_builders.h"

namespace shadel {
namespace {

constexpr uint32_t R = kRenderCommand, RB = kRenderCommand | kBenchCommand,
                   RBV = kEveryRenderingCommand, RV = kRenderCommand | kViewCommand;

// The image: size, mode, what is shown and how it is tone mapped.
void addImageOptions(std::vector<SettingOption>& t) {
    t.push_back(sizeOption());
    t.push_back(choiceOption<RenderMode>(
        "--mode", SETTING(mode),
        {{"forward", RenderMode::Forward},
         {"decoupled", RenderMode::Decoupled},
         {"reference", RenderMode::Reference}},
        RV,
        "forward shading; decoupled: shaded in shadel space, then rasterized; reference: "
        "path traced (unbiased, accumulated over --frames; needs ray queries)"));
    t.push_back(countOption("--ssaa", SETTING(ssaa), 1, 16, R, "NxN supersampled reference"));
    t.push_back(choiceOption<AntiAliasing>(
        "--aa", SETTING(aa),
        {{"auto", AntiAliasing::Auto}, {"none", AntiAliasing::None}, {"taa", AntiAliasing::Taa}},
        RBV,
        "anti-aliasing: taa (temporal: jittered frames accumulated with reprojection; jitter "
        "on by itself) | none | auto (none for render and bench, taa for view)"));
    t.push_back(floatOption("--taa-sharpen", SETTING(taaSharpen), FloatRange{0, 1}, RBV,
                            "TAA: unsharp mask over the displayed image (0: off)"));
    t.push_back(countOption("--aa-frames", SETTING(aaFrames), 1, 256, R,
                            "TAA: a still (--frames 1, static camera) accumulates this many "
                            "jittered frames and outputs the last"));
    t.push_back(choiceOption<Visualize>(
        "--visualize", SETTING(visualize),
        {{"none", Visualize::None},
         {"marking", Visualize::Marking},
         {"mips", Visualize::Mips},
         {"chunks", Visualize::Chunks},
         {"sheet", Visualize::Sheet},
         {"layer:radiance", Visualize::None}, // the image is the radiance layer
         {"layer:material", Visualize::LayerMaterial},
         {"reuse", Visualize::Reuse},
         {"light-count", Visualize::LightCount},
         {"spectra", Visualize::Spectra},
         {"blockers", Visualize::Blockers},
         {"gi", Visualize::Gi},
         {"rt-ao", Visualize::RtAo},
         {"particle-atlas", Visualize::ParticleAtlas},
         {"tiles", Visualize::Tiles}},
        R,
        "a debug view: reuse (decoupled: carried-over chunks grey; shaded ones tinted by why: "
        "red not reusable, green new, blue refresh, orange near a changed light, cyan RT "
        "history, yellow view turned); light-count; spectra (each tile's or chunk's shading "
        "permutation); gi (indirect light only, with --gi lpv); rt-ao (ray-traced AO only, "
        "with --rt-ao on); tiles (the 8x8 tile classes, with --screen-space on)"));
    t.push_back(exposureOption());
    t.push_back(choiceOption<Tonemap>("--tonemap", SETTING(tonemap),
                                      {{"aces-narkowicz", Tonemap::AcesNarkowicz},
                                       {"aces-hill", Tonemap::AcesHill},
                                       {"khr-pbr-neutral", Tonemap::KhrPbrNeutral},
                                       {"linear", Tonemap::Linear}},
                                      RBV,
                                      "the display curve after exposure (the glTF Sample "
                                      "Viewer's tone mappers)"));
    t.push_back(environmentOption());
    t.push_back(floatOption("--environment-intensity", SETTING(environmentIntensity),
                            FloatRange{0, 1e6}, RBV, "scale of the environment's light"));
    t.push_back(floatOption("--environment-rotation", SETTING(environmentRotationDegrees),
                            FloatRange{-360, 360}, RBV,
                            "degrees: the environment turned about +Y"));
    t.push_back(floatOption("--environment-spin", SETTING(environmentSpinDegrees),
                            FloatRange{-360, 360}, RBV,
                            "degrees the environment turns every frame (a turntable)"));
    t.push_back(backgroundOption());
}

// Decoupled shading: storage, the sheet, MIP selection, reuse.
void addDecoupledOptions(std::vector<SettingOption>& t) {
    t.push_back(choiceOption<MarkingMode>(
        "--marking", SETTING(marking),
        {{"auto", MarkingMode::Auto},
         {"raster", MarkingMode::Raster},
         {"visibility", MarkingMode::Visibility}},
        RBV,
        "decoupled: auto (visibility unless --occlusion or --screen-space needs raster) | "
        "raster (marking + reconstruction as raster passes) | visibility (visibility buffer, "
        "compute marking + resolve)"));
    t.push_back(countOption("--storage", SETTING(shadeStorageSize), 8, 65536, R,
                            "decoupled: shade storage side in shadels"));
    t.push_back(floatOption("--shading-bias", SETTING(shadingBias), kShadingBiasRange, RB,
                            "decoupled: fractional MIP bias (+ = fewer shadels)"));
    t.push_back(floatOption("--trilinear-band", SETTING(trilinearBand), kTrilinearBandRange, R,
                            "decoupled: LOD band blended between MIPs (1 = full trilinear); "
                            "narrower on plain rough materials the material rate shades coarser "
                            "(one MIP at its full bias)"));
    t.push_back(countOption("--material-samples", SETTING(materialSamples), 1, 64, R,
                            "decoupled: cap of material evaluations per shadel (procedurals are "
                            "supersampled in proportion to their footprint)"));
    t.push_back(countOption("--sheet", SETTING(sheetShadels), 8, 1u << 20, R,
                            "decoupled: virtual sheet side in shadels (64k..256k)"));
    t.push_back(floatOption("--forward-below", SETTING(forwardBelowPixels), kForwardBelowRange, R,
                            "decoupled: objects smaller on screen (pixels) are drawn forward "
                            "(0 = never)"));
    t.push_back(countOption("--allocation-counters", SETTING(allocationCounters), 1,
                            SHADEL_COUNTERS, R,
                            "decoupled: hashed storage counters to use (fewer only to test that "
                            "storage is shared)"));
    t.push_back(switchOption("--sheet-all-mips", SETTING(sheetAllMips), R,
                             "decoupled: give every visible object rects at all MIPs, not only "
                             "from the finest it can need (for comparison)"));
    t.push_back(onOffOption("--capacity-control", SETTING(capacityControl), R,
                            "decoupled: raise the shading bias when storage runs short"));
    t.push_back(onOffOption("--level-windows", SETTING(levelWindows), R,
                            "decoupled: a fine level's sheet rect holds only the part of the "
                            "level last frame's samples wanted, plus a margin (off: whole "
                            "levels)"));
    t.push_back(onOffOption("--material-rate", SETTING(materialRate), RB,
                            "decoupled: shade rough materials up to one MIP coarser: plain "
                            "(lighting-only) ones, and textured ones where the view magnifies "
                            "their textures (render/shadel/material_rate.h, texture_rate.h)"));
    t.push_back(onOffOption("--reuse", SETTING(reuse), R,
                            "decoupled: carry shadels whose inputs did not change over from last "
                            "frame (preserved layers)"));
    t.push_back(countOption("--reuse-refresh", SETTING(reuseRefreshPeriod), 1, 1024, RB,
                            "decoupled: reshade every carried-over chunk at least once per N "
                            "frames"));
    t.push_back(pixelOption("--inspect", SETTING(inspectX), SETTING(inspectY),
                            "print what the shading computed at that pixel (instance, "
                            "triangle, MIP, chunk, material, each light's contribution)"));
}

// Lights, shadows and transparency.
void addLightingOptions(std::vector<SettingOption>& t) {
    t.push_back(switchOption("--animate-lights", SETTING(animateLights), RB,
                             "move point and spot lights on small circles over the frames"));
    t.push_back(onOffOption("--shadows", SETTING(shadows), RBV,
                            "shadow maps (sun, spots, cascades); off: none"));
    t.push_back(choiceOption<bool>(
        "--sun", [](auto& t) -> auto& { return t.addDefaultSun; }, {{"auto", true}, {"off", false}},
        RBV, "a glTF file without a directional light gets a default sun (auto), or none"));
    t.push_back(choiceOption<OitMode>(
        "--oit", SETTING(oit), {{"wboit", OitMode::Wboit}, {"sorted", OitMode::Sorted}}, R,
        "transparency: weighted blended OIT with additiveness, or CPU-sorted back-to-front "
        "(the reference)"));
    t.push_back(shuffleDrawsOption());
    t.push_back(choiceOption<ParticleLighting>(
        "--particle-lighting", SETTING(particleLighting),
        {{"atlas", ParticleLighting::Atlas},
         {"pixel", ParticleLighting::Pixel},
         {"vertex", ParticleLighting::Vertex}},
        R,
        "lit particle sprites read a lightmap atlas lit per texel at an LOD from their screen "
        "size, or are lit per pixel / vertex"));
    t.push_back(
        onOffOption("--particles", SETTING(particles), R, "the scene's GPU particle emitters"));
    t.push_back(choiceOption<bool>(
        "--particle-resolution", SETTING(particleHalfRes), {{"half", true}, {"full", false}}, R,
        "particle sprites accumulated at half resolution in their own WBOIT targets, combined "
        "with the surfaces' in the composite"));
    t.push_back(countOption("--particle-atlas-size", SETTING(particleAtlasSize), 128, 8192, R,
                            "texels per side of the particle lightmap atlas"));
    t.push_back(
        choiceOption<LightCulling>("--light-culling", SETTING(lightCulling),
                                   {{"tiled", LightCulling::Tiled}, {"none", LightCulling::None}},
                                   R, "per-tile (forward) and per-chunk (shadel) light lists"));
    t.push_back(onOffOption("--light-grid", SETTING(lightGrid), RB,
                            "tiles and shadel chunks take their candidate lights from a "
                            "world-space light grid (off: each tests every light; the same "
                            "lists)"));
    t.push_back(onOffOption("--blockers", SETTING(lightBlockers), R,
                            "light blockers and portals stop the lights that list them"));
    t.push_back(choiceOption<Spectra>(
        "--spectra", SETTING(spectra),
        {{"auto", Spectra::Auto},
         {"on", Spectra::On},
         {"off", Spectra::Off},
         {"single", Spectra::Single}},
        R,
        "shading by permutations compiled with only the features each 16x16 tile (forward) or "
        "8x8-shadel chunk (decoupled) needs (single: one all-features permutation; off: the "
        "raster forward pass, the plain shadel shading; auto: on in decoupled frames with more "
        "than 64 lights, else off)"));
    t.push_back(choiceOption<bool>("--sun-shadows", SETTING(sunSoftShadows),
                                   {{"pcf", false}, {"pcss", true}}, R,
                                   "the sun's shadow filter (pcss: variable penumbra)"));
    t.push_back(onOffOption("--proxy-shadows", SETTING(proxyShadows), R,
                            "shadow views draw each mesh's proxy index set (positions only)"));
    t.push_back(onOffOption("--decals", SETTING(decals), R,
                            "the scene's projected box decals (base colour, normal, roughness, "
                            "ambient occlusion)"));
    t.push_back(countOption("--sun-cascades", SETTING(sunCascades), 1, 4, RB,
                            "the sun's shadow as N cascaded maps over the view depth (1: one map "
                            "fitted to the scene)"));
    t.push_back(onOffOption("--shadow-cache", SETTING(sunShadowCache), RB,
                            "keep the sun's shadow map while the sun and its casters stay put, "
                            "drawn once from every caster in its volume (off: redrawn every "
                            "frame from the casters whose shadow can reach the view)"));
    t.push_back(onOffOption("--fuse-tonemap", SETTING(fuseTonemap), RB,
                            "where nothing draws into the scene colour after the opaque shading "
                            "pass (no blended materials, particles, screen-space passes, debug "
                            "lines, --ssaa 1), that pass writes the display pixels itself and "
                            "the tonemap pass does not run (off: always a separate pass)"));
    t.push_back(choiceOption<ShadowCulling>(
        "--shadow-culling", SETTING(shadowCulling),
        {{"per-view", ShadowCulling::PerView}, {"whole-scene", ShadowCulling::WholeScene}}, R,
        "each sun cascade and shadow-casting spot draws its own GPU-culled casters, or all draw "
        "the sun's whole-scene list"));
    t.push_back(onOffOption("--spot-shadows", SETTING(spotShadows), R,
                            "shadow maps (one atlas) for the spots that cast shadows"));
}

// Global illumination, world scale, debug lines.
void addGiAndWorldOptions(std::vector<SettingOption>& t) {
    t.push_back(choiceOption<GiMode>("--gi", SETTING(gi),
                                     {{"lpv", GiMode::Lpv}, {"off", GiMode::Off}}, R,
                                     "light propagation volume GI (sun + shadow-casting spot "
                                     "RSMs, 3 camera cascades of 32^3)"));
    t.push_back(
        countOption("--gi-iterations", SETTING(giIterations), 0, 64, R, "GI: propagation steps"));
    t.push_back(onOffOption("--gi-snap", SETTING(giSnap), R,
                            "GI: snap the cascades to their cell size (off only to measure "
                            "swimming)"));
    t.push_back(onOffOption("--gi-blocker-cells", SETTING(giBlockerCells), R,
                            "GI: each tap tests only the light blockers of its 4^3 macro-cell "
                            "(off: every blocker, for comparison)"));
    t.push_back(onOffOption("--lod", SETTING(lod), R,
                            "pick each instance's LOD on the GPU by projected error"));
    t.push_back(floatOption("--lod-error", SETTING(lodErrorPixels), FloatRange{0.01, 64}, RB,
                            "with --lod on: each instance draws its coarsest LOD whose geometric "
                            "error projects below this many pixels (larger: fewer triangles, "
                            "coarser silhouettes; stats triangles_drawn)"));
    t.push_back(onOffOption("--occlusion", SETTING(occlusion), R,
                            "two-phase hierarchical-Z occlusion culling of instances"));
    t.push_back(debugLinesOption());
    t.push_back(pixelOption("--debug-lines-at", SETTING(debugLinesAtX), SETTING(debugLinesAtY),
                            "with --debug-lines lights|blockers, only the lights that reach the "
                            "surface seen at that pixel (and their blocker frusta)"));
}

// Ray tracing (render/raytracing).
void addRayTracingOptions(std::vector<SettingOption>& t) {
    t.push_back(onOffOption("--rt-shadows", SETTING(rt.shadows), R,
                            "ray-traced sun and shadow-casting spot shadows (in place of the "
                            "maps)"));
    t.push_back(onOffOption("--rt-ao", SETTING(rt.ao), R, "ray-traced ambient occlusion"));
    t.push_back(
        onOffOption("--rt-gi", SETTING(rt.gi), R, "one bounce of ray-traced diffuse light"));
    t.push_back(countOption("--rt-shadow-rays", SETTING(rt.shadowRays), 1, 64, R,
                            "sun rays per sample (1: hard shadows; more: soft, jittered over the "
                            "sun's disc)"));
    t.push_back(floatOption("--rt-sun-angle", SETTING(rt.sunAngleDegrees), FloatRange{0, 10}, R,
                            "half angle of the sun's disc in degrees (soft shadows)"));
    t.push_back(
        countOption("--rt-ao-rays", SETTING(rt.aoRays), 1, 256, R, "forward: AO rays per pixel"));
    t.push_back(floatOption("--rt-ao-radius", SETTING(rt.aoRadius), FloatRange{1e-4, 1e6}, R,
                            "AO ray length (scene units)"));
    t.push_back(
        countOption("--rt-gi-rays", SETTING(rt.giRays), 1, 256, R, "forward: GI rays per pixel"));
    t.push_back(onOffOption("--rt-filter", SETTING(rt.spatialFilter), R,
                            "forward: 3x3 depth-aware filter of the traced AO, GI and soft "
                            "shadows"));
    t.push_back(countOption("--rays-per-shadel", SETTING(rt.raysPerShadel), 1, 256, R,
                            "decoupled: AO / GI rays per shadel per frame"));
    t.push_back(countOption("--rt-shadel-mip-offset", SETTING(rt.shadelMipOffset), 0, 8, R,
                            "decoupled: the RT cache's MIP, this many levels coarser than the "
                            "finest the view needs"));
    t.push_back(floatOption("--rt-distance", SETTING(rt.distance), FloatRange{0, 1e9}, R,
                            "TLAS: instances within this distance of the camera (0 = all)"));
    // rgba16f counts exactly to 2048
    t.push_back(countOption("--rt-history-rays", SETTING(rt.historyRays), 1, 1024, R,
                            "decoupled: rays a cached texel accumulates, then reuses until its "
                            "inputs change"));
    t.push_back(countOption("--spp", SETTING(reference.samplesPerFrame), 1, 4096, R,
                            "reference: paths per pixel each frame adds to the accumulated mean"));
    t.push_back(countOption("--max-bounces", SETTING(reference.maxBounces), 0, 256, R,
                            "reference: surface hits a path continues through after the first "
                            "(0: direct light only); Russian roulette may end it earlier"));
    t.push_back(countOption("--seed", SETTING(reference.seed), 0, 0xFFFFFFFFu, R,
                            "reference: the random sequences' seed (the same seed, the same "
                            "image)"));
    t.push_back(onOffOption("--rt-animated-blas", SETTING(rt.animatedBlas), R,
                            "GPU-skinned meshes' BLASes refit as the pose changes (rebuilt every "
                            "8 refits; beyond 16 m at most every ceil(distance / 16 m) frames); "
                            "off: the bind pose's"));
    t.push_back(countOption("--blas-pool-mb", SETTING(rt.blasPoolMb), 1, 4096, R,
                            "BLAS memory pool size in MiB"));
    t.push_back(countOption("--blas-pool-limit", SETTING(rt.blasPoolLimit), 1, 1024, R,
                            "most BLAS pools (beyond: BLASes fall back to the least-detailed "
                            "LOD's)"));
}

// Screen-space passes, tiles and distance fields.
void addScreenSpaceOptions(std::vector<SettingOption>& t) {
    t.push_back(onOffOption("--screen-space", SETTING(screenSpace), R,
                            "thin G-buffer, sky, screen-space reflections and skin SSS"));
    t.push_back(onOffOption("--tile-classification", SETTING(tileClassification), R,
                            "run the screen-space passes only on the 8x8 tiles that need them"));
    t.push_back(onOffOption("--distance-fields", SETTING(distanceFieldLighting), R,
                            "mesh distance fields in a 3-D atlas: soft sun shadows and AO "
                            "(needs --screen-space on)"));
    t.push_back(floatOption("--df-shadow-start", SETTING(dfShadowStart), kDfDistanceRange, R,
                            "metres: with --distance-fields on, the sun's shadow comes from the "
                            "fields beyond this distance from the camera (0: everywhere), the "
                            "shadow map nearer"));
    t.push_back(floatOption("--df-residency", SETTING(dfResidencyDistance), kDfDistanceRange, R,
                            "metres: with --distance-fields on, only the fields of meshes with "
                            "an instance this near the camera stay in the 3-D atlas, streamed in "
                            "and out as the camera moves (0: every field, placed at load)"));
}

std::vector<SettingOption> buildTable() {
    std::vector<SettingOption> t;
    addImageOptions(t);
    addDecoupledOptions(t);
    addLightingOptions(t);
    addGiAndWorldOptions(t);
    addRayTracingOptions(t);
    addScreenSpaceOptions(t);
    return t;
}

} // namespace

const std::vector<SettingOption>& settingOptions() {
    static const std::vector<SettingOption> table = buildTable();
    return table;
}

} // namespace shadel
