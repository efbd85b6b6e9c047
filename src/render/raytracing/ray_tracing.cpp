#include "render/raytracing/ray_tracing.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <nlohmann/json.hpp>

#include "core/log.h"
#include "raytracing/rt_types.h"
#include "render/forward/forward_passes.h"
#include "render/raytracing/acceleration_structures.h"
#include "render/raytracing/rt_shadel_cache.h"
#include "render/renderer.h"
#include "render/skinning/skinning.h"
#include "rhi/rendering.h"

namespace shadel {

struct RayTracingState {
    RtFunctions fn;
    std::unique_ptr<BlasPools> pools;
    BlasSet blases;
    // GPU-skinned meshes: their own BLAS over the deformed vertices, refit as the pose changes
    // (created on the first frame with skinning: the renderer comes before the skinning state).
    AnimatedBlasSet animated;
    bool animatedCreated = false;
    std::vector<AnimatedBlasUpdate> animatedUpdates; // this frame's
    Tlas tlas;
    BufferHandle frame;           // gpu::RtFrame (host-visible)
    BufferHandle instanceLods;    // uint per instance: first index of its BLAS's LOD (host-visible)
    BufferHandle counters;        // gpu::RtCounters (readback)
    BufferHandle spotLights;      // uint per spot shadow index: its light (host-visible)
    uint32_t spotShadowCount = 0; // shadow-casting spots traced (--rt-shadows, --spot-shadows)
    // Forward path: the per-pixel terms (sun, AO, -, distance), the indirect light and the
    // shadow-casting spots' visibilities (8 bits each, rgba32ui).
    TextureHandle terms, indirect, spots;
    RenderTargetView termsTarget, indirectTarget, spotsTarget;
    TextureReadView termsRead, indirectRead, spotsRead;
    Pipeline pixelTerms;
    RtShadelCache shadelCache; // decoupled mode: the terms per shadel, accumulated over frames
    uint32_t raysLastFrame = 0;
    uint64_t raysTotal = 0;
    uint32_t framesTraced = 0;
    uint32_t fallbackInstances = 0; // TLAS instances this frame whose LOD used the fallback BLAS
};

void RayTracingStateDeleter::operator()(RayTracingState* state) const {
    delete state;
}

static const char* firstEffectFlag(const RenderSettings& settings) {
    const RtSettings& s = settings.rt;
    if (settings.mode == RenderMode::Reference) return "--mode reference";
    return s.shadows ? "--rt-shadows on" : s.ao ? "--rt-ao on" : "--rt-gi on";
}

static bool tracesPerPixel(const Renderer& r) {
    return r.settings.mode == RenderMode::Forward;
}

static void createPixelTargets(Renderer& r, RayTracingState& s) {
    Gpu& gpu = *r.gpu;
    TextureDesc d;
    d.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    d.width = r.internalWidth;
    d.height = r.internalHeight;
    d.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    d.name = "rt.pixelTerms";
    s.terms = createTexture(gpu, d);
    d.name = "rt.pixelIndirect";
    s.indirect = createTexture(gpu, d);
    d.format = VK_FORMAT_R32G32B32A32_UINT;
    d.name = "rt.pixelSpotShadows";
    s.spots = createTexture(gpu, d);
    if (!s.terms || !s.indirect || !s.spots)
        throw DeviceError("out of GPU memory for the ray-traced terms");
    s.termsTarget = createRenderTargetView(gpu, s.terms);
    s.indirectTarget = createRenderTargetView(gpu, s.indirect);
    s.termsRead = createReadView(gpu, s.terms);
    s.indirectRead = createReadView(gpu, s.indirect);
    s.spotsTarget = createRenderTargetView(gpu, s.spots);
    s.spotsRead = createReadView(gpu, s.spots);
    GraphicsPipelineDesc p;
    p.name = "rtPixelTerms";
    p.vertexShader = "forward_forward.vert.spv";
    p.fragmentShader = "raytracing_rt_pixel.frag.spv";
    p.colorFormats = {VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R16G16B16A16_SFLOAT,
                      VK_FORMAT_R32G32B32A32_UINT};
    p.depthFormat = VK_FORMAT_D32_SFLOAT;
    p.depthWrite = false;
    p.depthCompare = VK_COMPARE_OP_EQUAL; // the prepass resolved visibility
    p.dynamicCulling = true;              // per list side (drawCameraList), as the prepass
    s.pixelTerms = createGraphicsPipeline(gpu, p);
}

RayTracingStatePtr createRayTracing(Renderer& r, const GpuScene& scene) {
    Gpu& gpu = *r.gpu;
    const RtSettings& rt = r.settings.rt;
    if (!gpu.device.optional.rayQuery)
        throw InputError(format("%s: %s cannot trace rays (it lacks VK_KHR_ray_query or "
                                "VK_KHR_acceleration_structure)",
                                firstEffectFlag(r.settings), gpu.device.name.c_str()));
    RayTracingStatePtr state(new RayTracingState);
    RayTracingState& s = *state;
    s.fn = loadRtFunctions(gpu.device);
    s.pools = std::make_unique<BlasPools>(gpu, uint64_t(rt.blasPoolMb) << 20, rt.blasPoolLimit);
    buildBlases(gpu, s.fn, *s.pools, scene, s.blases);
    createTlas(gpu, s.fn, scene.instanceCount, s.tlas);
    s.frame = createBuffer(gpu, {"rt.frame", sizeof(gpu::RtFrame), 0, MemoryKind::Upload});
    s.instanceLods =
        createBuffer(gpu, {"rt.instanceLods", std::max<size_t>(scene.instanceCount, 1) * 4, 0,
                           MemoryKind::Upload});
    s.counters =
        createBuffer(gpu, {"rt.counters", sizeof(gpu::RtCounters), 0, MemoryKind::Readback});
    // Ray-traced spot shadows: the shadow-casting spots (GpuLight::shadowIndex, given in light
    // order at load), traced in place of their maps; without spot shadow maps there are none.
    std::vector<uint32_t> spotLights(LIGHT_MAX_SPOT_SHADOWS, 0);
    if (rt.shadows && r.settings.spotShadows)
        for (uint32_t i = 0; i < scene.lightInfo.size(); ++i)
            if (uint32_t k = scene.lightInfo[i].shadowIndex; k < LIGHT_MAX_SPOT_SHADOWS) {
                spotLights[k] = i;
                s.spotShadowCount = std::max(s.spotShadowCount, k + 1);
            }
    s.spotLights =
        createBuffer(gpu, {"rt.spotLights", spotLights.size() * 4, 0, MemoryKind::Upload});
    if (!s.frame || !s.instanceLods || !s.counters || !s.spotLights)
        throw DeviceError("out of GPU memory for the ray-tracing frame buffers");
    std::memcpy(mapped(gpu, s.spotLights), spotLights.data(), spotLights.size() * 4);
    if (tracesPerPixel(r))
        createPixelTargets(r, s);
    else if (r.settings.mode == RenderMode::Decoupled)
        createRtShadelCache(r, scene, s.spotShadowCount != 0, s.shadelCache);
    // (--mode reference: the TLAS alone, render/reference traces it)
    return state;
}

void destroyRayTracing(Renderer& r, RayTracingStatePtr& state) {
    if (!state) return;
    Gpu& gpu = *r.gpu;
    RayTracingState& s = *state;
    destroyRtShadelCache(r, s.shadelCache);
    destroyTlas(gpu, s.fn, s.tlas);
    destroyAnimatedBlases(gpu, s.fn, *s.pools, s.animated);
    destroyBlases(gpu, s.fn, *s.pools, s.blases);
    s.pools.reset();
    for (BufferHandle b : {s.frame, s.instanceLods, s.counters, s.spotLights})
        if (b) destroy(gpu, b);
    if (s.terms) {
        destroy(gpu, s.pixelTerms);
        destroy(gpu, s.termsTarget);
        destroy(gpu, s.indirectTarget);
        destroy(gpu, s.termsRead);
        destroy(gpu, s.indirectRead);
        destroy(gpu, s.spotsTarget);
        destroy(gpu, s.spotsRead);
        destroy(gpu, s.terms);
        destroy(gpu, s.indirect);
        destroy(gpu, s.spots);
    }
    state.reset();
}

// Distance from p to the box (0 inside).
static float distanceToBox(glm::vec3 p, glm::vec3 lo, glm::vec3 hi) {
    return glm::length(glm::max(glm::max(lo - p, p - hi), glm::vec3(0.0f)));
}

// Distance throttle of animated BLAS refits: within kRefitNearDistance of the camera a BLAS is
// refit every frame its pose changed; farther, at most once per ceil(distance /
// kRefitNearDistance) frames (so 2 beyond 16 m, 3 beyond 32 m, ...), up to kRefitMaxPeriod.
constexpr float kRefitNearDistance = 16.0f;
constexpr uint32_t kRefitMaxPeriod = 8;

static uint32_t refitPeriod(float distance) {
    float period = std::ceil(distance / kRefitNearDistance);
    return uint32_t(std::clamp(period, 1.0f, float(kRefitMaxPeriod)));
}

// Which animated BLASes are built or refit this frame (recorded at the top of rtBuildTlas).
static void planAnimatedBlasUpdates(Renderer& r, RayTracingState& s, const GpuScene& scene,
                                    const std::vector<float>& meshDistance) {
    s.animatedUpdates.clear();
    if (!r.skinning || !r.settings.rt.animatedBlas) return;
    if (!s.animatedCreated) {
        createAnimatedBlases(*r.gpu, s.fn, *s.pools, scene, skinnedMeshes(*r.skinning),
                             skinnedVerticesAddress(r, *r.skinning), s.animated);
        s.animatedCreated = true;
    }
    uint64_t pose = skinPoseVersion(*r.skinning);
    uint64_t frame = r.framesRendered;
    for (uint32_t k = 0; k < s.animated.blases.size(); ++k) {
        AnimatedBlas& a = s.animated.blases[k];
        if (a.built && a.builtPose == pose) continue; // the pose did not change
        if (a.built && frame - a.lastUpdateFrame < refitPeriod(meshDistance[a.mesh])) continue;
        bool rebuild = !a.built || a.refitsSinceBuild >= kRefitsPerRebuild;
        s.animatedUpdates.push_back({k, rebuild});
        a.built = true; // by the time the TLAS is built
        a.refitsSinceBuild = rebuild ? 0 : a.refitsSinceBuild + 1;
        a.builtPose = pose;
        a.lastUpdateFrame = frame;
        (rebuild ? s.animated.rebuilds : s.animated.refits)++;
    }
}

void prepareRayTracingFrame(Renderer& r, const GpuScene& scene, const CameraView& camera,
                            gpu::FrameConstants& constants) {
    Gpu& gpu = *r.gpu;
    RayTracingState& s = *r.rt;
    const RtSettings& rt = r.settings.rt;
    // The TLAS's instances: every instance within the ray-tracing distance of the camera, in
    // front of it or not (shadow and AO rays reach what the camera does not see). Each traces
    // the LOD the raster draws (--lod on: the coarsest whose error projects below the threshold
    // at its distance; off: LOD 0), so rays leave the very surface that is shaded: a coarser
    // BLAS of the same object would cut through it and shadow it (the least-detailed fallback
    // can, where its allocation failed).
    auto* out = static_cast<VkAccelerationStructureInstanceKHR*>(mapped(gpu, s.tlas.instances));
    auto* lods = static_cast<uint32_t*>(mapped(gpu, s.instanceLods));
    float pixelsPerUnit = std::abs(camera.proj[1][1]) * 0.5f * float(r.internalHeight);
    uint32_t count = 0;
    s.fallbackInstances = 0;
    if (r.skinning) { // animated BLASes: their nearest instance's distance throttles refits
        std::vector<float> meshDistance(scene.meshInfo.size(), INFINITY);
        for (uint32_t i = 0; i < scene.instanceCount; ++i) {
            const gpu::GpuInstance& inst = scene.instanceInfo[i];
            float& d = meshDistance[inst.mesh];
            d = std::min(d, distanceToBox(camera.position, inst.worldMin, inst.worldMax));
        }
        planAnimatedBlasUpdates(r, s, scene, meshDistance);
    }
    for (uint32_t i = 0; i < scene.instanceCount; ++i) {
        const gpu::GpuInstance& inst = scene.instanceInfo[i];
        const std::vector<int32_t>& chain = s.blases.meshLods[inst.mesh];
        float d = distanceToBox(camera.position, inst.worldMin, inst.worldMax);
        if (chain.empty() || (rt.distance > 0.0f && d > rt.distance)) continue;
        const gpu::GpuMeshLods& info = scene.lodInfo[inst.mesh];
        float scale =
            std::max({glm::length(glm::vec3(inst.model[0])), glm::length(glm::vec3(inst.model[1])),
                      glm::length(glm::vec3(inst.model[2]))});
        uint32_t lod = 0;
        while (r.settings.lod && lod + 1 < info.lodCount &&
               info.lod[lod + 1].error * scale * pixelsPerUnit <=
                   r.settings.lodErrorPixels * std::max(d, 1e-3f))
            ++lod;
        int32_t animated = inst.mesh < s.animated.byMesh.size() ? s.animated.byMesh[inst.mesh] : -1;
        int32_t b = chain[lod];
        if (b < 0 && animated < 0) continue; // no BLAS at all (even the least-detailed failed)
        VkAccelerationStructureInstanceKHR& o = out[count++];
        if (animated >= 0) { // skinned: the posed LOD 0
            const AnimatedBlas& a = s.animated.blases[animated];
            o.accelerationStructureReference = a.address;
            lods[i] = a.firstIndex;
        } else {
            const Blas& blas = s.blases.blases[b];
            s.fallbackInstances += blas.lod != lod;
            o.accelerationStructureReference = blas.address;
            lods[i] = blas.firstIndex;
        }
        for (int row = 0; row < 3; ++row)
            for (int col = 0; col < 4; ++col) o.transform.matrix[row][col] = inst.model[col][row];
        o.instanceCustomIndex = i;
        o.mask = 0xFF;
        o.instanceShaderBindingTableRecordOffset = 0;
        o.flags = VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR;
    }
    s.tlas.instanceCount = count;

    gpu::RtFrame f{};
    f.tlas = s.tlas.address;
    f.instanceLods = address(gpu, s.instanceLods);
    f.counters = address(gpu, s.counters);
    f.shadows = rt.shadows;
    f.ao = rt.ao;
    f.gi = rt.gi;
    f.shadowRays = rt.shadowRays;
    f.sunAngle = glm::radians(rt.sunAngleDegrees);
    f.aoRays = rt.aoRays;
    f.aoRadius = rt.aoRadius;
    f.giRays = rt.giRays;
    f.pixelTermsSlot = s.terms ? slot(gpu, s.termsRead).value : NO_TEXTURE;
    f.pixelIndirectSlot = s.indirect ? slot(gpu, s.indirectRead).value : NO_TEXTURE;
    f.frame = uint32_t(r.framesRendered);
    f.spatialFilter = rt.spatialFilter;
    f.normalOffset = 2e-4f;
    f.raysPerShadel = rt.raysPerShadel;
    f.spotShadowCount = s.spotShadowCount;
    f.spotLights = address(gpu, s.spotLights);
    f.pixelSpotSlot = s.spots ? slot(gpu, s.spotsRead).value : NO_TEXTURE;
    // The cache's MIP gives texels of 2^(offset - 1) .. 2^offset pixels at the instance's
    // nearest point (rt_shadel_cache.cpp, cacheLevel); 1 below is half the least of that.
    f.shadelTexelPixelScale = pixelsPerUnit / std::exp2(float(rt.shadelMipOffset) - 1.0f);
    if (s.shadelCache.terms) prepareRtShadelCache(r, scene, camera, s.shadelCache, f);
    std::memcpy(mapped(gpu, s.frame), &f, sizeof(f));
    constants.rt = address(gpu, s.frame);
}

void recordTlasBuild(Renderer& r, VkCommandBuffer cmd) {
    Gpu& gpu = *r.gpu;
    RayTracingState& s = *r.rt;
    vkCmdFillBuffer(cmd, vkBuffer(gpu, s.counters), 0, VK_WHOLE_SIZE, 0);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    recordAnimatedBlasUpdates(gpu, s.fn, cmd, s.animated, s.animatedUpdates);
    recordTlasBuild(gpu, s.fn, cmd, s.tlas);
}

void recordRayTracedPixels(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    RayTracingState& s = *r.rt;
    for (TextureHandle t : {s.terms, s.indirect, s.spots})
        imageBarrier(cmd, vkImage(gpu, t), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                     VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, 0,
                     VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                     VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
    // Cleared to 0: distance 0 means nothing traced.
    beginRendering(cmd, r.internalWidth, r.internalHeight,
                   {{vkView(gpu, s.termsTarget), true},
                    {vkView(gpu, s.indirectTarget), true},
                    {vkView(gpu, s.spotsTarget), true}},
                   {vkView(gpu, r.depthTarget)});
    bind(gpu, cmd, s.pixelTerms);
    pushConstants(gpu, cmd, RasterPush{frame, 0});
    drawCameraList(r, cmd, DRAW_LIST_OPAQUE);
    vkCmdEndRendering(cmd);
    for (TextureHandle t : {s.terms, s.indirect, s.spots})
        imageBarrier(
            cmd, vkImage(gpu, t), VK_IMAGE_ASPECT_COLOR_BIT,
            VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
            VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
            VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}

void recordRayTracedShadels(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    recordRtShadelTrace(r, cmd, frame, r.rt->shadelCache);
}

void finishRayTracingFrame(Renderer& r) {
    RayTracingState& s = *r.rt;
    gpu::RtCounters c{};
    std::memcpy(&c, mapped(*r.gpu, s.counters), sizeof(c));
    s.raysLastFrame = c.raysTraced;
    s.raysTotal += c.raysTraced;
    s.framesTraced++;
}

void rayTracingStats(const Renderer& r, nlohmann::json& stats) {
    const RayTracingState& s = *r.rt;
    PoolSetStats pools = s.pools->stats();
    stats["blas_count"] = s.blases.stats.built;
    stats["blas_bytes"] = s.blases.stats.bytes;
    stats["blas_pools"] = pools.poolCount;
    stats["blas_fallbacks"] = s.blases.stats.fallbacks;
    stats["tlas_instances"] = s.tlas.instanceCount;
    // Animated (skinned) BLASes, over the run: refits, and builds (each one's first included).
    stats["blas_refits"] = s.animated.refits;
    stats["blas_rebuilds"] = s.animated.rebuilds;
    stats["rays_traced"] = s.raysLastFrame;
    const RtSettings& rt = r.settings.rt;
    stats["rt"] = {
        {"shadows", rt.shadows},
        {"spot_shadows", s.spotShadowCount},
        {"ao", rt.ao},
        {"gi", rt.gi},
        {"blas_uncompacted_bytes", s.blases.stats.uncompactedBytes},
        {"blas_pool_bytes", pools.poolBytes},
        {"blas_pool_failed_allocations", pools.failedAllocations},
        {"meshes_without_blas", s.blases.stats.meshesWithoutBlas},
        {"tlas_fallback_instances", s.fallbackInstances},
        {"animated_blases", s.animated.blases.size()},
        {"animated_blases_without_room", s.animated.withoutRoom},
        {"animated_blas_updates_this_frame", s.animatedUpdates.size()},
        {"rays_traced_mean", s.framesTraced ? double(s.raysTotal) / s.framesTraced : 0.0}};
    if (s.shadelCache.terms)
        stats["rt"]["shadel_cache"] = {
            {"texels", s.shadelCache.texelsTraced},
            {"history_rays", rt.historyRays},
            {"instances", s.shadelCache.instancesCached},
            {"instances_without_room", s.shadelCache.instancesWithoutRoom},
            {"history_resets", s.shadelCache.historyResets},
            {"rays_per_shadel", rt.raysPerShadel},
            {"mip_offset", rt.shadelMipOffset}};
}

} // namespace shadel
