#include "render/renderer.h"

#include <cstring>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include "bake/bake_cache.h"
#include "bake/cache_folder.h"
#include "common/print_labels.h"
#include "core/log.h"
#include "render/background/background.h"
#include "render/forward/forward_passes.h"
#include "render/lighting/light_animation.h"
#include "render/oit/oit.h"
#include "render/particles/particles.h"
#include "render/post/tone_curve.h"
#include "render/post/tonemap.h"
#include "render/screenspace/screen_space.h"
#include "render/shadel/decoupled.h"
#include "render/shadel/visibility.h"
#include "render/streaming/texture_streaming.h"

namespace shadel {

static bool usesVisibilityBuffer(const RenderSettings& s) {
    return s.mode == RenderMode::Decoupled && s.marking == MarkingMode::Visibility;
}

static void createTargets(Renderer& r) {
    Gpu& gpu = *r.gpu;
    r.internalWidth = r.settings.width * r.settings.ssaa;
    r.internalHeight = r.settings.height * r.settings.ssaa;
    uint32_t maxDim = gpu.device.properties.limits.maxImageDimension2D;
    if (r.internalWidth > maxDim || r.internalHeight > maxDim)
        throw InputError(format("--size %ux%u with --ssaa %u needs %ux%u targets; this device "
                                "allows at most %u",
                                r.settings.width, r.settings.height, r.settings.ssaa,
                                r.internalWidth, r.internalHeight, maxDim));
    auto need = [](auto handle, const char* what) {
        if (!handle) throw DeviceError(format("out of GPU memory for %s", what));
        return handle;
    };
    TextureDesc hdr;
    hdr.name = "sceneColor";
    hdr.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    hdr.width = r.internalWidth;
    hdr.height = r.internalHeight;
    // (copied from by render/transmission)
    hdr.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    // compute resolve, screen space, tile shading
    if (usesVisibilityBuffer(r.settings) || r.settings.screenSpace || usesTileShading(r) ||
        r.settings.mode == RenderMode::Reference) // (the path tracer writes its mean)
        hdr.usage |= VK_IMAGE_USAGE_STORAGE_BIT;
    r.hdr = need(createTexture(gpu, hdr), "the scene colour target");
    r.hdrTarget = createRenderTargetView(gpu, r.hdr);
    r.hdrRead = createReadView(gpu, r.hdr);

    TextureDesc depth;
    depth.name = "sceneDepth";
    depth.format = VK_FORMAT_D32_SFLOAT;
    depth.width = r.internalWidth;
    depth.height = r.internalHeight;
    depth.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    r.depth = need(createTexture(gpu, depth), "the depth target");
    r.depthTarget = createDepthTargetView(gpu, r.depth);
    r.depthRead = createReadView(gpu, r.depth);

    if (forwardMayFuseTonemap(r)) { // forward shading's display pixels (render/post/tonemap.h)
        TextureDesc display;
        display.name = "displayColor";
        display.format = VK_FORMAT_R8G8B8A8_UNORM;
        display.width = r.settings.width;
        display.height = r.settings.height;
        display.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
        r.display = need(createTexture(gpu, display), "the display target");
        r.displayTarget = createRenderTargetView(gpu, r.display);
    }

    // The sun's whole-scene map: a one-map shadow atlas (render/lighting/shadow_atlas.h).
    r.sunShadow =
        createShadowAtlas(gpu, "sunShadow", r.settings.shadowMapSize, r.settings.shadowMapSize,
                          "forward_forward.vert.spv", r.alphaMasked);
}

// --capture names of the targets every frame has (render/debug/capture.h).
static void registerTargetCaptures(Renderer& r) {
    Gpu& gpu = *r.gpu;
    // After tonemap (which reads a target that allows storage in GENERAL layout).
    VkImageLayout hdrLayout = (desc(gpu, r.hdr).usage & VK_IMAGE_USAGE_STORAGE_BIT)
                                  ? VK_IMAGE_LAYOUT_GENERAL
                                  : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    registerTextureCapture(
        r.captures, gpu, "hdr", "scene colour before tonemapping (EXR)", CaptureKind::Hdr,
        [&r] { return r.hdr; }, hdrLayout);
    registerTextureCapture(
        r.captures, gpu, "depth", "reversed-Z depth, 1 = near (EXR)", CaptureKind::Depth,
        [&r] { return r.depth; }, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    registerTextureCapture(
        r.captures, gpu, "shadow", "the sun's shadow map depth (EXR)", CaptureKind::Depth,
        [&r] { return r.sunShadow.texture; }, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
}

// --marking auto: visibility, unless a feature that needs the raster prepass is on.
// The settings' "auto" choices, for this scene.
static RenderSettings resolveSettings(RenderSettings s, const GpuScene& scene) {
    if (s.marking == MarkingMode::Auto)
        s.marking = s.occlusion || s.screenSpace ? MarkingMode::Raster : MarkingMode::Visibility;
    // Spectra where they pay (render/lighting/feature_spectra.h): decoupled frames that would
    // cull lights per chunk, i.e. tiled culling with more lights than per-subgroup lists take
    // (render/lighting/light_culling.h); and whenever their debug view is asked for.
    if (s.spectra == Spectra::Auto) {
        bool perChunk = s.mode == RenderMode::Decoupled && s.lightCulling == LightCulling::Tiled &&
                        scene.lightInfo.size() > LIGHT_SUBGROUP_MAX_LIGHTS;
        s.spectra = perChunk || s.visualize == Visualize::Spectra ? Spectra::On : Spectra::Off;
    }
    if (s.mode == RenderMode::Reference) { // render/reference: traced, no raster lighting
        s.shadows = false;                 // shadow rays instead of maps
        s.gi = GiMode::Off;                // every bounce traced
        s.rt = RtSettings{.blasPoolMb = s.rt.blasPoolMb, .blasPoolLimit = s.rt.blasPoolLimit};
        s.lod = false; // rays meet LOD 0, the finest surface
        s.occlusion = s.screenSpace = s.particles = s.decals = false;
        s.distanceFieldLighting = false;
        s.lightCulling = LightCulling::None;
        s.spectra = Spectra::Off;
        s.fuseTonemap = false;
    }
    if (!s.shadows) { // --shadows off: no shadow map of any light
        s.spotShadows = false;
        s.sunCascades = 1;
        s.sunSoftShadows = false;
    }
    return s;
}

void initRenderer(Renderer& r, Gpu& gpu, const RenderSettings& requested, const GpuScene& scene) {
    const RenderSettings settings = resolveSettings(requested, scene);
    r.gpu = &gpu;
    r.settings = settings;
    r.alphaMasked = hasAlphaMaskedMaterials(scene);
    r.sunShadowCache = {}; // (a Renderer reused after destroyRenderer has a new, undrawn atlas)
    if (settings.width == 0 || settings.height == 0 || settings.ssaa == 0)
        throw InputError("--size and --ssaa must be positive");
    if (settings.spectra != Spectra::Off && settings.lightCulling != LightCulling::Tiled)
        throw InputError("--spectra on|single needs --light-culling tiled (the tile pass "
                         "records each tile's features)");
    bool tileSpectra = settings.spectra != Spectra::Off && settings.mode == RenderMode::Forward;
    if (tileSpectra && settings.occlusion)
        throw InputError("--spectra on|single needs --occlusion off (tile shading reads the "
                         "visibility buffer, which the phase-2 prepass does not write)");
    if (tileSpectra && settings.rt.enabled())
        throw InputError("--spectra on|single with --rt-*: tile shading does not read the "
                         "ray-traced terms yet; use --spectra off");
    if (tileSpectra && settings.screenSpace)
        throw InputError("--spectra on|single with --screen-space on: the thin G-buffer needs "
                         "the depth prepass the tile path replaces; use one of them");
    if (tileSpectra && settings.inspectX >= 0)
        throw InputError("--inspect needs --spectra off (the prints come from the raster "
                         "forward pass)");
    if (settings.visualize == Visualize::Spectra && settings.spectra == Spectra::Off)
        throw InputError("--visualize spectra needs --spectra on or single");
    if (settings.occlusion && usesVisibilityBuffer(settings))
        throw InputError("--occlusion on needs --marking raster (the phase-2 prepass writes "
                         "depth only, not the visibility buffer)");
    createTargets(r);
    registerTargetCaptures(r);
    r.maxDraws = std::max<uint32_t>(scene.instanceCount, 1);
    VkDeviceSize drawBytes =
        VkDeviceSize(DRAW_LIST_COUNT) * r.maxDraws * sizeof(gpu::DrawIndexedCommand);
    r.draws = createBuffer(
        gpu, {"draws.camera", DRAW_SIDE_COUNT * drawBytes, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT});
    r.shadowDraws =
        createBuffer(gpu, {"draws.sunShadow", drawBytes, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT});
    r.drawCounts = createBuffer(gpu, {"draws.counts", (DRAW_CAMERA_SLOTS + DRAW_LIST_COUNT) * 4,
                                      VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT});
    r.frameConstants =
        createBuffer(gpu, {"frameConstants", sizeof(gpu::FrameConstants), 0, MemoryKind::Upload});
    r.pixels =
        createBuffer(gpu, {"pixels.readback", VkDeviceSize(settings.width) * settings.height * 4, 0,
                           MemoryKind::Readback});
    if (!r.draws || !r.shadowDraws || !r.drawCounts || !r.frameConstants || !r.pixels)
        throw DeviceError("out of GPU memory for the renderer's frame buffers");
    createTonemapPipeline(r);
    createBackgroundPipelines(r);
    initShaderMessages(gpu, r.messages);
    initFrameRecorder(gpu, r.recorder, settings.timing, std::max(1u, settings.recordingThreads));
    if (settings.mode == RenderMode::Decoupled) r.decoupled = createDecoupled(r, scene);
    // Tile shading (--spectra on|single, forward) reads the visibility buffer too.
    if (usesVisibilityBuffer(settings) || usesTileShading(r)) r.visibility = createVisibility(r);
    const bool reference = settings.mode == RenderMode::Reference; // traces every surface
    if (!reference) r.oit = createOit(r, scene);
    if (!reference) r.transmission = createTransmission(r, scene);
    r.particles = createParticles(r, scene);
    r.lightCulling = createLightCulling(r, scene);
    r.spotShadows = createSpotShadows(r, scene);
    r.sunCascades = createSunCascades(r, scene);
    if (usesTileShading(r) || usesChunkSpectra(r)) r.spectra = createFeatureSpectra(r);
    // After the decoupled and spectra states: whether forward pixels read tile lists depends on
    // them (forwardSplitsTileLights).
    r.forwardSplitsTileLights = forwardSplitsTileLights(r, scene);
    createForwardPipelines(r);
    if (settings.gi == GiMode::Lpv) r.gi = createGi(r, scene);
    r.culling = createCulling(r, scene);
    r.decals = createDecals(r, scene); // after the decoupled state (its queue's capacity)
    r.debugLines = createDebugLines(r);
    if (settings.rt.enabled() || reference) r.rt = createRayTracing(r, scene);
    if (reference) r.reference = createReference(r, scene); // (its TLAS: the ray-tracing state's)
    createScreenSpace(r);
    r.taa = createTaa(r);
    // Last: prefiltering a new environment takes seconds, and every check above that can refuse
    // the settings (a device without ray queries, ...) answers first.
    createEnvironment(gpu, r.environment, settings, scene, usableCacheFolder(settings.cacheDir));
}

void destroyRenderer(Renderer& r) {
    if (!r.gpu) return;
    Gpu& gpu = *r.gpu;
    vkDeviceWaitIdle(gpu.device.device);
    destroyReference(r, r.reference);
    destroyRayTracing(r, r.rt);
    destroyFeatureSpectra(r, r.spectra);
    destroySpotShadows(r, r.spotShadows);
    destroySunCascades(r, r.sunCascades);
    destroyDecals(r, r.decals);
    destroyLightCulling(r, r.lightCulling);
    destroyDebugLines(r, r.debugLines);
    destroyScreenSpace(r);
    destroyTaa(r, r.taa);
    if (r.distanceFields) destroyDistanceFields(r, *r.distanceFields);
    r.distanceFields.reset();
    if (r.stencilEffects) destroyStencilEffects(r, *r.stencilEffects);
    r.stencilEffects.reset();
    if (r.skinning) destroySkinning(r, *r.skinning);
    r.skinning.reset();
    if (r.pointsLines) destroyPointsLines(r, *r.pointsLines);
    r.pointsLines.reset();
    if (r.gi) destroyGi(r, r.gi);
    r.captures = {}; // its sources refer to what is destroyed below
    if (r.visibility) destroyVisibility(r, r.visibility);
    destroyParticles(r, r.particles);
    destroyOit(r, r.oit);
    destroyTransmission(r, r.transmission);
    if (r.decoupled) destroyDecoupled(r, r.decoupled);
    destroyCulling(r, r.culling);
    destroyFrameRecorder(r.recorder);
    destroyShaderMessages(gpu, r.messages);
    destroyForwardPipelines(r);
    destroy(gpu, r.tonemap);
    destroyBackgroundPipelines(r);
    destroyEnvironment(gpu, r.environment);
    for (BufferHandle b : {r.draws, r.shadowDraws, r.drawCounts, r.frameConstants, r.pixels})
        destroy(gpu, b);
    if (r.liveLights) destroy(gpu, r.liveLights);
    destroySceneEdits(r);
    destroy(gpu, r.hdrTarget);
    destroy(gpu, r.hdrRead);
    destroy(gpu, r.displayTarget);
    if (r.display) destroy(gpu, r.display);
    r.display = {}; // (forward only: a Renderer initialised again may not create it)
    r.displayTarget = {};
    destroy(gpu, r.depthTarget);
    destroy(gpu, r.depthRead);
    destroyShadowAtlas(gpu, r.sunShadow);
    for (TextureHandle t : {r.hdr, r.depth}) destroy(gpu, t);
    r.gpu = nullptr;
}

// The sun's orthographic shadow volume, fitted to the scene bounds.
static glm::mat4 sunViewProj(const GpuScene& scene, glm::vec3 dir, float& texelWorldSize,
                             uint32_t mapSize) {
    Aabb b = scene.bounds.valid() ? scene.bounds : Aabb{glm::vec3(-1), glm::vec3(1)};
    glm::vec3 center = b.center();
    float radius = std::max(glm::length(b.extent()) * 0.5f, 1e-3f);
    glm::vec3 up = std::abs(dir.y) > 0.99f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    glm::mat4 view = glm::lookAt(center - dir * radius * 2.0f, center, up);
    glm::mat4 proj =
        glm::orthoRH_ZO(-radius, radius, -radius, radius, radius * 0.5f, radius * 3.5f);
    texelWorldSize = 2.0f * radius / float(mapSize);
    return proj * view;
}

// Degrees about +Y: --environment-rotation, turned by --environment-spin every frame.
static float environmentRotationThisFrame(const Renderer& r) {
    return r.settings.environmentRotationDegrees +
           r.settings.environmentSpinDegrees * float(r.framesRendered);
}

static gpu::FrameConstants makeFrameConstants(Renderer& r, const GpuScene& scene,
                                              const CameraView& camera) {
    Gpu& gpu = *r.gpu;
    gpu::FrameConstants f{};
    f.view = camera.view;
    f.proj = camera.proj;
    f.viewProj = camera.proj * camera.view;
    f.invViewProj = glm::inverse(f.viewProj);
    float texel = 0.0f;
    SunEdit sun = currentSun(r, scene); // as loaded, or edited (render/scene_edits.h)
    f.sunViewProj = sunViewProj(scene, sun.direction, texel, r.settings.shadowMapSize);
    auto planes = frustumPlanes(f.viewProj);
    auto shadowPlanes = frustumPlanes(f.sunViewProj);
    shadowPlanes[4] = glm::vec4(0, 0, 0, 1); // depth clamp keeps casters in front of the near plane
    for (int i = 0; i < 6; ++i) f.frustumPlanes[i] = planes[i], f.shadowPlanes[i] = shadowPlanes[i];
    f.cameraPosition = camera.position;
    f.exposure = r.settings.exposure;
    f.sunDirection = sun.direction;
    f.sunColor = sun.color;
    f.sunShadowSlot =
        scene.sunCastsShadow && r.settings.shadows ? slot(gpu, r.sunShadow.read).value : NO_TEXTURE;
    f.shadowTexelSize = texel;
    f.skyColor = scene.skyColor;
    f.ambientColor = scene.ambientColor;
    f.tonemap = uint32_t(r.settings.tonemap);
    f.backgroundEnvironment = r.settings.backgroundEnvironment ? 1u : 0u;
    f.backgroundColor = r.skyColor;
    setEnvironmentView(r.environment, r.settings.environmentIntensity,
                       environmentRotationThisFrame(r)); // (the viewer edits them)
    f.environment = r.environment.constants;
    f.lightCount = scene.lightCount;
    f.instanceCount = scene.instanceCount;
    f.viewportSize = glm::vec2(r.internalWidth, r.internalHeight);
    f.invViewportSize = 1.0f / f.viewportSize;
    f.frameIndex = uint32_t(r.framesRendered); // this renderer's (renderers may share the device)
    f.visualize = uint32_t(r.settings.visualize);
    f.inspectPixel = INSPECT_OFF;
    if (r.settings.inspectX >= 0 && r.settings.inspectY >= 0) // the SSAA sample at its corner
        f.inspectPixel = uint32_t(r.settings.inspectX) * r.settings.ssaa |
                         (uint32_t(r.settings.inspectY) * r.settings.ssaa) << 16;
    f.vertices = address(gpu, scene.vertices);
    f.indices = address(gpu, scene.indices);
    f.visibilityVertices = address(gpu, scene.visibilityVertices);
    f.meshes = address(gpu, scene.meshes);
    f.instances = address(gpu, scene.instances);
    f.materials = address(gpu, scene.materials);
    f.lights = address(gpu, scene.lights);
    f.messages = shaderMessagesAddress(gpu, r.messages);
    return f;
}

// Live lights (--animate-lights, edits): this frame's lights into the upload buffer, and what
// changed since the last frame (the decoupled path reshades what changed lights reach). Also
// binds the edited materials.
static void updateLights(Renderer& r, const GpuScene& scene, gpu::FrameConstants& constants) {
    r.changedLightVolumes.clear();
    const std::vector<gpu::GpuLight>& base = applySceneEdits(r, scene, constants);
    if (r.edits.sunChanged) // the sun reaches everything
        r.changedLightVolumes.push_back(
            glm::vec4(0.0f, 0.0f, 0.0f, std::numeric_limits<float>::infinity()));
    bool live = r.settings.animateLights || !r.edits.lights.empty();
    if (!live || scene.lightInfo.empty()) return;
    std::vector<gpu::GpuLight> lights =
        r.settings.animateLights ? animatedLights(base, r.framesRendered) : base;
    if (!r.liveLights) {
        r.liveLights = createBuffer(
            *r.gpu, {"lights.live", lights.size() * sizeof(gpu::GpuLight), 0, MemoryKind::Upload});
        if (!r.liveLights) throw DeviceError("out of GPU memory for the live lights");
    }
    std::memcpy(mapped(*r.gpu, r.liveLights), lights.data(), lights.size() * sizeof(gpu::GpuLight));
    constants.lights = address(*r.gpu, r.liveLights);
    // The first live frame after unedited ones compares against the lights as loaded.
    const std::vector<gpu::GpuLight>& before =
        r.lightsLastFrame.empty() ? scene.lightInfo : r.lightsLastFrame;
    if (r.framesRendered > 0) {
        std::vector<glm::vec4> changed = changedLightVolumes(before, lights);
        r.changedLightVolumes.insert(r.changedLightVolumes.end(), changed.begin(), changed.end());
    }
    r.lightsLastFrame = std::move(lights);
}

// One frame, top to bottom. Forward: cull, shadow, depth prepass, shading, tonemap.
// Decoupled replaces shading with marking, allocation, work queues, shadel shading and
// reconstruction (render/shadel/decoupled.h). With TAA the camera is jittered and the resolve
// runs before the tonemap (render/taa).
// The frame's CPU frontends in order (lights, streaming, culling, decoupled allocation,
// transparency, shadows, ray tracing...): they fill the frame constants the passes read.
// `streamingMs`: the texture streaming frontend's CPU time.
static gpu::FrameConstants prepareFrame(Renderer& r, const GpuScene& scene,
                                        const CameraView& camera, double& streamingMs) {
    gpu::FrameConstants constants;
    {
        auto timer = cpuScope(r, "constants + lights");
        constants = makeFrameConstants(r, scene, camera);
        if (r.skinning) constants.vertices = skinnedVerticesAddress(r, *r.skinning); // every view
        updateLights(r, scene, constants);
        // A turned or dimmed environment relights every surface (as a changed sun does).
        glm::vec2 view(r.settings.environmentIntensity, environmentRotationThisFrame(r));
        if (r.framesRendered > 0 && view != r.environmentViewLastFrame)
            r.changedLightVolumes.push_back(
                glm::vec4(0.0f, 0.0f, 0.0f, std::numeric_limits<float>::infinity()));
        r.environmentViewLastFrame = view;
    }
    // Before beginFrame (streaming rebinds texture slots in the set this frame uses) and before
    // the decoupled frontend (which must not carry over shading of re-streamed textures).
    r.changedMaterials.clear();
    // The streaming frontend's CPU time (its pass may be recorded on a worker: rhi/frame.h).
    if (r.streaming) {
        auto timer = cpuScope(r, "texture streaming");
        double streamingStart = threadCpuMs();
        prepareTextureStreaming(*r.streaming, camera, float(r.internalHeight), constants);
        r.changedMaterials = restreamedMaterials(*r.streaming);
        if (VkSemaphore bound = takeTextureStreamingWait(*r.streaming)) // sparse page binds
            r.recorder.waitOnce.push_back(bound);
        streamingMs += threadCpuMs() - streamingStart;
    }
    // Edited materials reshade like re-streamed ones.
    if (!r.edits.materialsChanged.empty()) {
        r.changedMaterials.resize(r.edits.materialsChanged.size(), 0);
        for (size_t i = 0; i < r.edits.materialsChanged.size(); ++i)
            r.changedMaterials[i] |= r.edits.materialsChanged[i];
    }
    noteShadowCasterChanges(r, scene); // before the shadow maps decide to keep theirs
    {
        auto timer = cpuScope(r, "light culling");
        constants.lighting = prepareLightCulling(
            r, scene, r.lightsLastFrame.empty() ? scene.lightInfo : r.lightsLastFrame, constants);
    }
    if (r.gi) {
        auto timer = cpuScope(r, "gi");
        prepareGiFrame(r, scene, camera, constants);
    }
    if (r.distanceFields && r.settings.distanceFieldLighting) { // render/distance_fields
        auto timer = cpuScope(r, "distance fields");
        updateDistanceFieldResidency(r, *r.distanceFields, camera.position);
        constants.distanceFields = distanceFieldFrameAddress(r, *r.distanceFields);
        constants.dfShadowStart = r.settings.dfShadowStart;
    }
    if (r.decoupled) {
        auto timer = cpuScope(r, "decoupled coarse allocation");
        prepareDecoupledFrame(r, scene, camera, constants);
    }
    {
        auto timer = cpuScope(r, "transparency + particles");
        prepareTransparentDraws(r, scene, camera);
        prepareTransmissionDraws(r, scene, camera);
        prepareParticleFrame(r);
    }
    {
        auto timer = cpuScope(r, "culling + decals");
        prepareSunShadowMap(r, scene, constants);
        prepareCullingFrame(r, scene, constants);
        constants.decals = prepareDecalFrame(r, constants);
    }
    constants.debugLines = debugLinesAddress(r);
    if (r.rt) {
        auto timer = cpuScope(r, "ray tracing");
        prepareRayTracingFrame(r, scene, camera, constants);
    }
    if (r.reference) prepareReferenceFrame(r, camera);
    return constants;
}

// When and how long the CPU worked on a frame, for its result.
struct FrameCpuTimes {
    std::chrono::steady_clock::time_point start;
    double threadStartMs = 0.0, startMs = 0.0, prepareMs = 0.0, streamingMs = 0.0;
};

// After the frame's submission: its pixels read back, every technique's per-frame statistics
// and bookkeeping, the timings.
static FrameResult finishFrame(Renderer& r, FrameCpuTimes t) {
    Gpu& gpu = *r.gpu;
    FrameRecorder& rec = r.recorder;
    auto msSince = [](std::chrono::steady_clock::time_point at) {
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - at)
            .count();
    };
    FrameResult result;
    result.passes = rec.passes;
    result.tonemapFused = r.tonemapFused;
    result.recordingMs = rec.recordingMs;
    result.recordingWorkers = rec.workerTimings;
    result.frameMs = rec.frameMs;
    result.startMs = t.startMs;
    result.cpuPrepareMs = t.prepareMs;
    // CPU cost: the whole call minus the time spent waiting for the GPU (submit-per-pass waits
    // inside the passes, so this is an upper bound there).
    result.cpuFrameMs = t.prepareMs + std::max(0.0, msSince(t.start) - t.prepareMs - rec.gpuWaitMs);
    auto finishing = cpuScope(r, "finish: read back, stats");
    result.shaderAsserts = collectShaderMessages(gpu, r.messages);
    result.prints = r.messages.prints;
    result.transparentDecoupledDraws = decoupledTransparentDraws(r);
    result.transparentDraws =
        uint32_t(transparentDrawOrder(r).size()) + result.transparentDecoupledDraws;
    if (r.decoupled) finishDecoupledFrame(r);
    if (r.taa) finishTaaFrame(r);
    readLightCullingStats(r);
    readFeatureSpectraStats(r);
    readDecalStats(r);
    finishCullingFrame(r);
    if (r.rt) finishRayTracingFrame(r);
    finishScreenSpaceFrame(r);
    if (r.streaming) {
        double finishStart = threadCpuMs();
        finishTextureStreamingFrame(*r.streaming);
        t.streamingMs += threadCpuMs() - finishStart;
    }
    finishSceneEdits(r);
    r.framesRendered++;
    size_t bytes = size_t(r.settings.width) * r.settings.height * 4;
    result.rgba.resize(bytes);
    std::memcpy(result.rgba.data(), mapped(gpu, r.pixels), bytes);
    for (size_t i = 3; i < bytes; i += 4) result.pixelsCovered += result.rgba[i] != 0;
    finishing.stop();
    result.cpuThreadMs = threadCpuMs() - t.threadStartMs;
    result.cpuScopes = std::move(r.cpuScopes);
    double recorderStartMs =
        std::chrono::duration<double, std::milli>(rec.frameStart - t.start).count();
    for (CpuScope submit : rec.submits) { // from the recorder's frame start
        submit.startMs += recorderStartMs;
        result.cpuScopes.push_back(std::move(submit));
    }
    result.cpuStreamingMs = t.streamingMs;
    return result;
}

FrameResult renderFrame(Renderer& r, const GpuScene& scene, const CameraView& unjittered) {
    Gpu& gpu = *r.gpu;
    const CameraView camera = r.taa ? prepareTaaFrame(r, unjittered) : unjittered;
    double threadStart = threadCpuMs();
    using Clock = std::chrono::steady_clock;
    auto msSince = [](Clock::time_point t) {
        return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
    };
    Clock::time_point cpuStart = Clock::now();
    double startMs = std::chrono::duration<double, std::milli>(cpuStart - r.createdAt).count();
    r.cpuScopes.clear();
    r.frontendTaken.clear();
    r.frameCpuStart = cpuStart;
    r.recorder.timeRecording = r.settings.cpuScopes;
    r.sceneIndices = scene.indices;
    r.sceneVisibilityIndices = scene.visibilityIndices;
    // Uncovered pixels: the environment, or the radiance the display curve shows as the solid
    // --background colour (the clears of the colour passes use it too).
    r.skyColor = r.settings.backgroundEnvironment
                     ? scene.skyColor
                     : radianceForDisplay(r.settings.backgroundColor, r.settings.exposure,
                                          r.settings.tonemap);
    double streamingMs = 0.0;
    gpu::FrameConstants constants = prepareFrame(r, scene, camera, streamingMs);
    std::memcpy(mapped(gpu, r.frameConstants), &constants, sizeof(constants));
    uint64_t frame = address(gpu, r.frameConstants);
    double prepareMs = msSince(cpuStart);
    if (r.nextFrame) { // the next frame's frontend beside this frame's backend
        const CameraView& next = r.nextFrame->camera;
        prefetchCoarseVisit(r, scene, r.taa ? taaNextFrameView(r, next) : next,
                            r.nextFrame->sceneMoves);
        r.nextFrame.reset();
    }

    r.tonemapFused = tonemapFusedThisFrame(r); // (after the transparent draws are prepared)
    prepareForwardPipelines(r);                // (their first use: this output's pipelines)
    prepareResolvePipelines(r);
    FrameRecorder& rec = r.recorder;
    auto declaring = cpuScope(r, "declare passes");
    beginFrame(rec);
    if (r.debugLines) // --debug-lines: any later pass may append segments
        pass(rec, "debugLinesClear", [&](VkCommandBuffer cmd) { recordDebugLinesClear(r, cmd); });
    if (r.streaming) // landed texture loads copied in, the feedback buffer cleared
        pass(rec, "textureStreaming", [&](VkCommandBuffer cmd) {
            double recordStart = threadCpuMs();
            recordTextureStreaming(*r.streaming, cmd);
            streamingMs += threadCpuMs() - recordStart;
        });
    if (r.skinning) // skinned vertices for every view below (render/skinning)
        pass(rec, "skinning", [&](VkCommandBuffer cmd) { recordSkinning(r, cmd); });
    pass(rec, "instanceCull",
         [&](VkCommandBuffer cmd) { recordInstanceCull(r, cmd, frame, scene); });
    if (sunShadowMapThisFrame(r)) // kept from an earlier frame unless it changed (render/lighting)
        pass(rec, "shadowMap", [&](VkCommandBuffer cmd) { recordShadowMap(r, cmd, frame); });
    if (r.sunCascades) // --sun-cascades 2..4 (render/lighting/sun_cascades.h)
        pass(rec, "sunCascades", [&](VkCommandBuffer cmd) { recordSunCascades(r, cmd, frame); });
    if (r.rt) pass(rec, "rtBuildTlas", [&](VkCommandBuffer cmd) { recordTlasBuild(r, cmd); });
    if (spotShadowMapsThisFrame(r)) // shadow-casting spots, one atlas (render/lighting)
        pass(rec, "spotShadowMaps",
             [&](VkCommandBuffer cmd) { recordSpotShadowMaps(r, cmd, frame); });
    if (r.gi) { // light propagation volumes (render/gi): RSMs, injection, propagation
        pass(rec, "giReflectiveShadowMaps",
             [&](VkCommandBuffer cmd) { recordGiReflectiveShadowMaps(r, cmd, frame); });
        pass(rec, "giInject", [&](VkCommandBuffer cmd) { recordGiInjection(r, cmd); });
        pass(rec, "giPropagate", [&](VkCommandBuffer cmd) { recordGiPropagation(r, cmd); });
    }
    if (r.visibility)
        pass(rec, "visibilityPrepass",
             [&](VkCommandBuffer cmd) { recordVisibilityPrepass(r, cmd, frame); });
    else
        pass(rec, "depthPrepass", [&](VkCommandBuffer cmd) { recordDepthPrepass(r, cmd, frame); });
    if (r.settings.occlusion) recordOcclusionPasses(r, rec, frame, scene);
    if (lightCullingThisFrame(r)) // depth bounds per tile: after the occlusion passes' 2nd phase
        pass(rec, "lightCulling", [&](VkCommandBuffer cmd) { recordLightCulling(r, cmd, frame); });
    recordThinGBufferPass(r, rec, frame);               // --screen-space on (render/screenspace)
    if (r.rt && r.settings.mode == RenderMode::Forward) // sun visibility, AO, GI per pixel
        pass(rec, "rtPixelTerms",
             [&](VkCommandBuffer cmd) { recordRayTracedPixels(r, cmd, frame); });
    if (r.settings.mode == RenderMode::Forward) // decal lists per tile (render/decals)
        recordDecalCulling(r, rec, frame);      // (decoupled: in recordDecoupledShading)
    if (usesTileShading(r)) { // forward, per-tile permutations (render/lighting/feature_spectra.h)
        pass(rec, "tileShading", [&](VkCommandBuffer cmd) { recordTileShading(r, cmd, frame); });
    } else if (r.settings.mode == RenderMode::Forward) { // (tonemap fused: display pixels)
        pass(rec, "forwardShading",
             [&](VkCommandBuffer cmd) { recordForwardShading(r, cmd, frame); });
    } else if (r.reference) { // path traced, accumulated over frames (render/reference)
        pass(rec, "referencePathTrace",
             [&](VkCommandBuffer cmd) { recordReferencePathTrace(r, cmd, frame); });
    } else {
        recordDecoupledMarking(r, rec, frame); // what the frame's pixels read, in shadel space
        if (r.rt) // the RT cache the shadel shading reads, where marked (render/raytracing)
            pass(rec, "rtShadelTrace",
                 [&](VkCommandBuffer cmd) { recordRayTracedShadels(r, cmd, frame); });
        recordDecoupledShading(r, rec, frame, scene);
    }
    recordParticlePasses(r, rec, frame);    // GPU particles: simulation, atlas lighting
    recordScreenSpacePasses(r, rec, frame); // sky, SSR, SSS over classified tiles
    recordStencilEffects(r, rec, frame, constants.viewProj); // water, character outline
    recordPointsLines(r, rec, frame);        // glTF points and lines, forward in both modes
    recordTransmissionPasses(r, rec, frame); // over a mipmapped copy of the opaque scene colour
    recordTransparencyPasses(r, rec, frame); // blended materials, after every opaque surface
    if (r.debugLines) recordDebugLinePasses(r, rec, frame, scene, constants.lightCount);
    recordParticleAtlasView(r, rec, frame);    // --visualize particle-atlas
    if (r.taa) recordTaaPasses(r, rec, frame); // jittered frames accumulated (render/taa)
    if (!r.tonemapFused) // else forward shading or the resolve wrote display pixels (render/post)
        pass(rec, "tonemap", [&](VkCommandBuffer cmd) { recordTonemap(r, cmd, frame); });
    else if (r.settings.mode == RenderMode::Forward) // (the resolve wrote the readback itself)
        pass(rec, "displayReadback", [&](VkCommandBuffer cmd) { recordDisplayReadback(r, cmd); });
    if (r.decoupled) recordDecoupledPostPasses(r, rec, frame);
    declaring.stop();
    {
        auto timer = cpuScope(r, "end frame: record, submit, wait");
        endFrame(rec);
    }

    return finishFrame(r, {cpuStart, threadStart, startMs, prepareMs, streamingMs});
}

} // namespace shadel
