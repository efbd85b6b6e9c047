// Ray tracing (render/raytracing): BLASes per mesh LOD in TLSF pools with the
// least-detailed fallback, the per-frame TLAS, and the ray-traced effects of the forward path.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "gpu_test_env.h"
#include "scene_files.h"

using namespace shadel;
using namespace shadel::test;

namespace {

constexpr uint32_t kW = 160, kH = 90; // lavapipe traces slowly: keep RT images small

RenderOptions rtOptions(const std::string& scene = "builtin:default") {
    RenderOptions o = renderOptions(scene, RenderMode::Forward, kW, kH);
    o.progress = false;
    return o;
}

uint64_t lodCount(const RenderRun& run) {
    return run.stats["blas_count"].get<uint64_t>() + run.stats["blas_fallbacks"].get<uint64_t>() +
           run.stats["rt"]["meshes_without_blas"].get<uint64_t>();
}

double meanLuma(const RenderRun& run) {
    const auto& p = run.frames.back().rgba;
    double sum = 0;
    size_t n = 0;
    for (size_t i = 0; i < p.size(); i += 4, ++n)
        sum += 0.2126 * p[i] + 0.7152 * p[i + 1] + 0.0722 * p[i + 2];
    return sum / double(std::max<size_t>(n, 1));
}

size_t lineCount(const std::string& s) {
    size_t n = 0;
    for (char c : s) n += c == '\n';
    return n;
}

} // namespace

TEST(RayTracing, BuildsCompactedBlasesAndTracesOneSunRayPerPixel) {
    SHADEL_REQUIRE(sharedGpu().device.optional.rayQuery,
                   "ray query (VK_KHR_ray_query) on the device");
    RenderOptions o = rtOptions();
    o.rt.shadows = true;
    RenderRun run = renderChecked(o);
    const auto& s = run.stats;
    EXPECT_GT(s["blas_count"].get<uint64_t>(), 0u);
    EXPECT_EQ(s["blas_fallbacks"].get<uint64_t>(), 0u);
    EXPECT_EQ(s["rt"]["meshes_without_blas"].get<uint64_t>(), 0u);
    EXPECT_GE(s["blas_pools"].get<uint64_t>(), 1u);
    // Compaction: the pools hold no more than the builds needed (lavapipe's BLASes do not
    // shrink when compacted; other drivers' do).
    EXPECT_GT(s["blas_bytes"].get<uint64_t>(), 0u);
    EXPECT_LE(s["blas_bytes"].get<uint64_t>(), s["rt"]["blas_uncompacted_bytes"].get<uint64_t>());
    // --rt-distance 0: every instance is in the TLAS.
    EXPECT_EQ(s["tlas_instances"].get<uint64_t>(), s["instances"].get<uint64_t>());
    // Hard shadows: one ray per opaque pixel (the sky traces none).
    uint64_t rays = s["rays_traced"].get<uint64_t>();
    EXPECT_GT(rays, 0u);
    EXPECT_LE(rays, uint64_t(kW) * kH);
    EXPECT_GE(rays, s["pixels_covered"].get<uint64_t>() / 2);

    // AO with 4 rays adds exactly 4 rays to each of those pixels.
    o.rt.ao = true;
    o.rt.aoRays = 4;
    RenderRun withAo = renderChecked(o);
    EXPECT_EQ(withAo.stats["rays_traced"].get<uint64_t>(), 5 * rays);
    EXPECT_EQ(lodCount(withAo), lodCount(run));
}

TEST(RayTracing, TlasKeepsTheInstancesWithinTheRayTracingDistance) {
    SHADEL_REQUIRE(sharedGpu().device.optional.rayQuery,
                   "ray query (VK_KHR_ray_query) on the device");
    RenderOptions o = rtOptions();
    o.width = 64;
    o.height = 36;
    o.rt.shadows = true;
    o.rt.distance = 4.0f;
    RenderRun near = renderChecked(o);
    uint64_t kept = near.stats["tlas_instances"].get<uint64_t>();
    std::printf("--rt-distance 4: %llu of %llu instances in the TLAS\n", (unsigned long long)kept,
                (unsigned long long)near.stats["instances"].get<uint64_t>());
    EXPECT_GT(kept, 0u);
    EXPECT_LT(kept, near.stats["instances"].get<uint64_t>());
}

TEST(RayTracing, PoolLimitFallsBackToTheLeastDetailedBlas) {
    SHADEL_REQUIRE(sharedGpu().device.optional.rayQuery,
                   "ray query (VK_KHR_ray_query) on the device");
    RenderOptions o = rtOptions();
    o.rt.shadows = true;
    RenderRun full = renderChecked(o);
    uint64_t fullBytes = full.stats["blas_bytes"].get<uint64_t>();
    // One pool of a third of what every BLAS needs: the finest LODs cannot all fit.
    o.rt.blasPoolMb = 1;
    o.rt.blasPoolLimit = std::max<uint32_t>(1, uint32_t(fullBytes / 3 >> 20));
    ASSERT_LT(uint64_t(o.rt.blasPoolLimit) << 20, fullBytes) << "the scene's BLASes fit anyway";
    RenderRun limited = renderChecked(o);
    const auto& s = limited.stats;
    EXPECT_GT(s["blas_fallbacks"].get<uint64_t>(), 0u);
    EXPECT_LE(s["blas_pools"].get<uint64_t>(), o.rt.blasPoolLimit);
    EXPECT_LE(s["blas_bytes"].get<uint64_t>(), uint64_t(o.rt.blasPoolLimit) << 20);
    EXPECT_EQ(s["rt"]["blas_pool_failed_allocations"].get<uint64_t>(),
              s["blas_fallbacks"].get<uint64_t>() + s["rt"]["meshes_without_blas"].get<uint64_t>());
    // Every LOD is accounted for: built, or falling back.
    EXPECT_EQ(lodCount(limited), lodCount(full));
    EXPECT_EQ(s["rt"]["meshes_without_blas"].get<uint64_t>(), 0u);
    EXPECT_EQ(s["tlas_instances"].get<uint64_t>(), full.stats["tlas_instances"].get<uint64_t>());
    // Nothing corrupted: coarser occluders move shadow edges a little, no more.
    double db = psnr(limited.frames.back().rgba, full.frames.back().rgba);
    std::printf("%u pool(s) of 1 MiB: %llu fallbacks, %.2f dB against unlimited\n",
                o.rt.blasPoolLimit, (unsigned long long)s["blas_fallbacks"].get<uint64_t>(), db);
    EXPECT_GE(db, 25.0);
}

TEST(RayTracing, SunShadowsAgreeWithTheShadowMap) {
    SHADEL_REQUIRE(sharedGpu().device.optional.rayQuery,
                   "ray query (VK_KHR_ray_query) on the device");
    RenderOptions o = rtOptions();
    RenderRun shadowMap = renderChecked(o);
    o.rt.shadows = true;
    RenderRun traced = renderChecked(o);
    double db = psnr(traced.frames.back().rgba, shadowMap.frames.back().rgba);
    std::printf("RT sun shadows vs shadow map: %.2f dB\n", db);
    EXPECT_GE(db, 30.0);
    EXPECT_LT(db, 99.0) << "the traced shadows changed nothing: were they applied?";
}

TEST(RayTracing, AmbientOcclusionDarkensAndGiBrightens) {
    SHADEL_REQUIRE(sharedGpu().device.optional.rayQuery,
                   "ray query (VK_KHR_ray_query) on the device");
    RenderOptions o = rtOptions();
    o.rt.shadows = true;
    RenderRun plain = renderChecked(o);
    o.rt.ao = true;
    RenderRun ao = renderChecked(o);
    o.rt.ao = false;
    o.rt.gi = true;
    RenderRun gi = renderChecked(o);
    std::printf("mean luma: plain %.2f, AO %.2f, GI %.2f\n", meanLuma(plain), meanLuma(ao),
                meanLuma(gi));
    EXPECT_LT(meanLuma(ao), meanLuma(plain) - 0.2);
    EXPECT_GT(meanLuma(gi), meanLuma(plain) + 0.2);
}

TEST(RayTracing, FlagsWithoutRayQueryAreOneClearError) {
    std::string err;
    EXPECT_EQ(runShadel("SHADEL_DISABLE_RAY_QUERY=1",
                        "render --scene builtin:default --size 32x18 --rt-shadows on", err),
              2);
    EXPECT_EQ(lineCount(err), 1u) << err;
    EXPECT_NE(err.find("--rt-shadows on"), std::string::npos) << err;
    EXPECT_NE(err.find("VK_KHR_ray_query"), std::string::npos) << err;
    // Without --rt-* the same device renders.
    EXPECT_EQ(
        runShadel("SHADEL_DISABLE_RAY_QUERY=1", "render --scene builtin:default --size 32x18", err),
        0)
        << err;
    EXPECT_EQ(runShadel("", "render --size 32x18 --rt-ao maybe", err), 2);
    EXPECT_NE(err.find("--rt-ao maybe"), std::string::npos) << err;
    EXPECT_EQ(runShadel("", "render --size 32x18 --blas-pool-mb 0", err), 2);
    EXPECT_NE(err.find("--blas-pool-mb 0"), std::string::npos) << err;
    EXPECT_EQ(runShadel("", "render --size 32x18 --rays-per-shadel 0", err), 2);
    EXPECT_NE(err.find("--rays-per-shadel"), std::string::npos) << err;
}

namespace {

// The shadel path's AO alone (--visualize rt-ao) at 96x54: its cache holds every visible
// instance's whole shadel space, several texels per pixel at this size.
RenderOptions shadelAoOptions(uint32_t frames, uint32_t raysPerShadel, uint32_t mipOffset) {
    RenderOptions o = renderOptions("builtin:default", RenderMode::Decoupled, 96, 54);
    o.progress = false;
    o.rt.aoRadius = 4.0f;
    o.rt.shadelMipOffset = mipOffset;
    o.frames = frames;
    o.rt.ao = true;
    o.rt.raysPerShadel = raysPerShadel;
    o.visualize = Visualize::RtAo;
    o.forwardBelowPixels = 0; // every instance in shadel space: all of them read the cache
    return o;
}

} // namespace

TEST(RayTracing, ShadelAoConvergesToTheHighRayReference) {
    SHADEL_REQUIRE(sharedGpu().device.optional.rayQuery,
                   "ray query (VK_KHR_ray_query) on the device");
    RenderRun reference = renderChecked(shadelAoOptions(1, 256, 4));
    RenderRun one = renderChecked(shadelAoOptions(1, 1, 4));
    RenderRun sixteen = renderChecked(shadelAoOptions(16, 1, 4));
    double db1 = psnr(one.frames.back().rgba, reference.frames.back().rgba);
    double db16 = psnr(sixteen.frames.back().rgba, reference.frames.back().rgba);
    std::printf("shadel AO vs 256 rays/shadel: 1 frame %.2f dB, 16 frames %.2f dB; rays/frame "
                "%llu (reference %llu)\n",
                db1, db16, (unsigned long long)sixteen.stats["rays_traced"].get<uint64_t>(),
                (unsigned long long)reference.stats["rays_traced"].get<uint64_t>());
    EXPECT_GE(db16, 35.0);
    EXPECT_GT(db16, db1 + 3.0) << "the history did not accumulate";
    EXPECT_EQ(sixteen.stats["rt"]["shadel_cache"]["instances_without_room"].get<uint64_t>(), 0u);
    EXPECT_GT(sixteen.stats["rt"]["shadel_cache"]["instances"].get<uint64_t>(), 0u);
}

// Decoupled reuse while the RT cache converges (a still camera): a carried-over chunk keeps the
// RT terms it was shaded with, so it is reshaded each time the cache under it doubles its rays
// (raytracing/rt_history.glsl). Against the converged image, reuse on must stay close to reuse
// off (which reshades every chunk every frame) on every frame; carrying the terms over until the
// round-robin refresh trailed it by 5-9 dB.
TEST(RayTracing, ShadelReuseFollowsTheRtCacheAsItConverges) {
    SHADEL_REQUIRE(sharedGpu().device.optional.rayQuery,
                   "ray query (VK_KHR_ray_query) on the device");
    auto options = [](uint32_t frames, uint32_t rays, bool reuse) {
        RenderOptions o = shadelAoOptions(frames, rays, 2);
        o.width = 160;
        o.height = 90;
        o.rt.aoRadius = 1.0f;
        o.reuse = reuse;
        return o;
    };
    RenderRun converged = renderChecked(options(1, 256, false));
    RenderRun on = renderChecked(options(8, 1, true));
    RenderRun off = renderChecked(options(8, 1, false));
    double gapSum = 0.0, worstGap = 0.0;
    for (size_t f = 1; f < on.frames.size(); ++f) {
        double dbOn = psnr(on.frames[f].rgba, converged.frames.back().rgba);
        double dbOff = psnr(off.frames[f].rgba, converged.frames.back().rgba);
        std::printf("frame %zu vs 256 rays: reuse on %.2f dB, off %.2f dB\n", f, dbOn, dbOff);
        gapSum += dbOff - dbOn;
        worstGap = std::max(worstGap, dbOff - dbOn);
    }
    double meanGap = gapSum / double(on.frames.size() - 1);
    double reuse = on.stats["reuse_fraction"].get<double>();
    double rtHistory = on.stats["shaded_because"]["rt_history"].get<double>();
    std::printf("gap mean %.2f dB, worst %.2f dB; reuse %.3f, reshaded for RT history %.3f\n",
                meanGap, worstGap, reuse, rtHistory);
    EXPECT_LE(meanGap, 2.5);
    EXPECT_LE(worstGap, 4.0);
    EXPECT_GT(rtHistory, 0.0);
    EXPECT_GE(reuse, 0.3) << "reuse must still carry most chunks over";
}

// Mean absolute change between consecutive frames from frame `first` on (colour channels).
double flickerFrom(const RenderRun& run, size_t first) {
    double sum = 0;
    size_t n = 0;
    for (size_t f = std::max<size_t>(first, 1); f < run.frames.size(); ++f) {
        const auto& a = run.frames[f - 1].rgba;
        const auto& b = run.frames[f].rgba;
        for (size_t i = 0; i < a.size(); i += 4)
            for (int c = 0; c < 3; ++c, ++n) sum += std::abs(double(a[i + c]) - double(b[i + c]));
    }
    return sum / double(std::max<size_t>(n, 1));
}

// A static camera, so every change between frames is the estimator's noise: the shadel path's
// history converges, the per-pixel forward path draws new rays every frame. (Under
// --camera-path orbit the frame-to-frame change at 96x54 is dominated by the motion itself for
// both paths; docs/raytracing/README.md has the figures.)
TEST(RayTracing, ShadelAoFlickersLessThanPerPixelAtTheSameRayBudget) {
    SHADEL_REQUIRE(sharedGpu().device.optional.rayQuery,
                   "ray query (VK_KHR_ray_query) on the device");
    RenderRun shadel = renderChecked(shadelAoOptions(16, 1, 3));
    double shadelRays = shadel.stats["rt"]["rays_traced_mean"].get<double>();
    // Forward: as many rays per pixel as the shadel path traced per covered pixel (at least 1).
    RenderOptions f = shadelAoOptions(16, 1, 3);
    f.mode = RenderMode::Forward;
    double covered = double(shadel.stats["pixels_covered"].get<uint64_t>());
    f.rt.aoRays = std::max<uint32_t>(1, uint32_t(std::lround(shadelRays / covered)));
    RenderRun forward = renderChecked(f);
    double forwardRays = forward.stats["rt"]["rays_traced_mean"].get<double>();
    double flickerShadel = flickerFrom(shadel, 8);
    double flickerForward = flickerFrom(forward, 8);
    std::printf("AO flicker (frames 8-15, static): shadel %.3f (%.0f rays/frame), forward %.3f "
                "(%u rays/pixel + 3x3 filter, %.0f rays/frame)\n",
                flickerShadel, shadelRays, flickerForward, f.rt.aoRays, forwardRays);
    EXPECT_GE(forwardRays, shadelRays * 0.9);
    EXPECT_GT(flickerForward, 0.0);
    EXPECT_LE(flickerShadel, 0.5 * flickerForward);
}

namespace {

// The AO image (--visualize rt-ao) of builtin:default at 192x108 over 8 frames of --camera-path
// orbit (40 degrees in all: the image moves by about 18 pixels a frame).
RenderOptions orbitAoOptions(RenderMode mode) {
    RenderOptions o = renderOptions("builtin:default", mode, 192, 108);
    o.progress = false;
    o.frames = 8;
    o.cameraPath = CameraPath::Orbit;
    o.rt.ao = true;
    o.visualize = Visualize::RtAo;
    o.forwardBelowPixels = 0; // every instance in shadel space: all of them read the cache
    return o;
}

// Flicker under a moving camera. Frame t's noise is its difference from a converged render of
// the same frame by the same path (`reference`: its 256-ray cache, or 64 rays per pixel with the
// same 3x3 filter): what the camera motion changes and the path's own bias are in both, so only
// the estimator's noise is left. The flicker is the mean absolute frame-to-frame change of that
// noise, over the colour channels (0..255) of frames 1..n-1. It does not follow surfaces from
// frame to frame: the shadel path's noise, fixed on the surfaces, still moves over the pixels
// with the camera and counts as change, so the measure errs against the shadel path.
double noiseFlicker(const RenderRun& run, const RenderRun& reference) {
    double sum = 0;
    size_t n = 0;
    for (size_t f = 1; f < run.frames.size(); ++f) {
        const auto& a0 = run.frames[f - 1].rgba;
        const auto& a1 = run.frames[f].rgba;
        const auto& r0 = reference.frames[f - 1].rgba;
        const auto& r1 = reference.frames[f].rgba;
        for (size_t i = 0; i < a1.size(); i += 4)
            for (int c = 0; c < 3; ++c, ++n) {
                double noise0 = double(a0[i + c]) - double(r0[i + c]);
                double noise1 = double(a1[i + c]) - double(r1[i + c]);
                sum += std::abs(noise1 - noise0);
            }
    }
    return sum / double(std::max<size_t>(n, 1));
}

double meanPsnr(const RenderRun& run, const RenderRun& reference) {
    double sum = 0;
    for (size_t f = 0; f < run.frames.size(); ++f)
        sum += psnr(run.frames[f].rgba, reference.frames[f].rgba);
    return sum / double(std::max<size_t>(run.frames.size(), 1));
}

double raysOverTheRun(const RenderRun& run) {
    return run.stats["rt"]["rays_traced_mean"].get<double>() * double(run.frames.size());
}

} // namespace

// With a moving camera the shadel path's AO flickers at most half
// as much as the per-pixel forward path's at the same ray budget (all rays of the run, counted
// on the GPU). The shadel path: its cache one MIP coarser than the default
// (--rt-shadel-mip-offset 3), 2 rays per shadel per frame; forward: the fewest whole rays per
// pixel that spend at least as many rays (1 here), with its 3x3 filter.
TEST(RayTracing, ShadelAoFlickersLessThanPerPixelUnderAnOrbitingCamera) {
    SHADEL_REQUIRE(sharedGpu().device.optional.rayQuery,
                   "ray query (VK_KHR_ray_query) on the device");
    RenderOptions s = orbitAoOptions(RenderMode::Decoupled);
    s.rt.shadelMipOffset = 3;
    s.rt.raysPerShadel = 2;
    RenderRun shadel = renderChecked(s);
    s.rt.raysPerShadel = 256; // every texel done on the frame it comes into view
    RenderRun shadelReference = renderChecked(s);
    RenderOptions f = orbitAoOptions(RenderMode::Forward);
    double shadelRays = raysOverTheRun(shadel);
    double fragmentsPerRay = double(shadel.stats["pixels_covered"].get<uint64_t>());
    f.rt.aoRays =
        std::max<uint32_t>(1, uint32_t(std::ceil(shadelRays / double(s.frames) / fragmentsPerRay)));
    RenderRun forward = renderChecked(f);
    uint32_t forwardRaysPerPixel = f.rt.aoRays;
    f.rt.aoRays = 64;
    RenderRun forwardReference = renderChecked(f);
    double forwardRays = raysOverTheRun(forward);
    double flickerShadel = noiseFlicker(shadel, shadelReference);
    double flickerForward = noiseFlicker(forward, forwardReference);
    std::printf("AO flicker, orbit 192x108, 8 frames: shadel %.3f (%.0f rays, %.2f dB mean vs its "
                "reference), forward %.3f (%u rays/pixel + 3x3 filter, %.0f rays, %.2f dB); "
                "ratio %.3f\n",
                flickerShadel, shadelRays, meanPsnr(shadel, shadelReference), flickerForward,
                forwardRaysPerPixel, forwardRays, meanPsnr(forward, forwardReference),
                flickerShadel / flickerForward);
    // The camera moved: each converged frame differs from the one before (28 dB apart here).
    for (size_t t = 1; t < shadelReference.frames.size(); ++t)
        EXPECT_LT(psnr(shadelReference.frames[t - 1].rgba, shadelReference.frames[t].rgba), 35.0);
    EXPECT_GE(forwardRays, shadelRays) << "forward must not have the smaller budget";
    EXPECT_GT(flickerForward, 0.0);
    EXPECT_LE(flickerShadel, 0.5 * flickerForward);
}

namespace {

double luma(const std::vector<uint8_t>& p, size_t i) {
    return 0.2126 * p[i] + 0.7152 * p[i + 1] + 0.0722 * p[i + 2];
}

// Pixels that `shadowed` makes darker than `unshadowed` by more than `by` (luma), and those it
// makes brighter by more than 2.
struct ShadowPixels {
    std::vector<size_t> darker;
    size_t brighter = 0;
};
ShadowPixels shadowPixels(const RenderRun& shadowed, const RenderRun& unshadowed, double by) {
    const auto& a = shadowed.frames.back().rgba;
    const auto& b = unshadowed.frames.back().rgba;
    ShadowPixels s;
    for (size_t i = 0; i < a.size(); i += 4) {
        double d = luma(b, i) - luma(a, i);
        if (d > by) s.darker.push_back(i);
        s.brighter += d < -2.0;
    }
    return s;
}

} // namespace

namespace {

// A thin post (4 cm square, 1.5 m tall) on a square floor `floorSize` metres wide, a sun along
// (0.6, -0.6, 0.5) and a camera looking down at the post's foot: the floor fills the view at
// either size, so only the sun's shadow map resolution differs (its whole-scene map is fitted
// to the scene: ~20 cm texels over 400 m, ~2 cm over 40 m).
std::string thinPostScene(const std::string& name, float floorSize) {
    std::vector<float> f;
    std::vector<uint16_t> indices = {0, 2, 1, 0, 3, 2};
    float h = floorSize / 2;
    f.insert(f.end(), {-h, 0, -h, h, 0, -h, h, 0, h, -h, 0, h});
    f.insert(f.end(), {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0});
    std::vector<float> postNormals;
    const float postCentre[3] = {0.0f, 0.75f, 0.0f}, postHalf[3] = {0.02f, 0.75f, 0.02f};
    appendBox(postCentre, postHalf, f, postNormals, indices);
    f.insert(f.end(), postNormals.begin(), postNormals.end());
    using nlohmann::json;
    auto view = gltfBufferView;
    auto accessor = gltfAccessor;
    auto rotationTowards = gltfRotationTowards;
    size_t ib = f.size() * 4;
    json doc;
    doc["asset"] = {{"version", "2.0"}};
    doc["scene"] = 0;
    doc["scenes"] = {{{"nodes", {0, 1, 2, 3}}}};
    doc["extensionsUsed"] = {"KHR_lights_punctual"};
    doc["extensions"]["KHR_lights_punctual"]["lights"] = {
        {{"type", "directional"}, {"intensity", 3.0}, {"color", {1, 1, 1}}}};
    glm::vec3 eye(-1.2f, 2.5f, -2.4f), target(0.5f, 0.0f, 0.5f);
    doc["nodes"] = {{{"mesh", 0}, {"name", "floor"}},
                    {{"mesh", 1}, {"name", "post"}},
                    {{"name", "sun"},
                     {"rotation", rotationTowards(glm::vec3(0.6f, -0.6f, 0.5f))},
                     {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}},
                    {{"name", "camera"},
                     {"camera", 0},
                     {"translation", {eye.x, eye.y, eye.z}},
                     {"rotation", rotationTowards(target - eye)}}};
    doc["cameras"] = {{{"type", "perspective"},
                       {"perspective", {{"yfov", 0.9}, {"znear", 0.05}, {"zfar", 1000.0}}}}};
    doc["bufferViews"] = {view(0, 48),    view(48, 48), view(96, 288),
                          view(384, 288), view(ib, 12), view(ib + 12, 72)};
    const int f32 = 5126, u16 = 5123;
    doc["accessors"] = {accessor(0, f32, 4, "VEC3"),   accessor(1, f32, 4, "VEC3"),
                        accessor(2, f32, 24, "VEC3"),  accessor(3, f32, 24, "VEC3"),
                        accessor(4, u16, 6, "SCALAR"), accessor(5, u16, 36, "SCALAR")};
    doc["accessors"][0]["min"] = {-h, 0, -h};
    doc["accessors"][0]["max"] = {h, 0, h};
    doc["accessors"][2]["min"] = {-0.02, 0.0, -0.02};
    doc["accessors"][2]["max"] = {0.02, 1.5, 0.02};
    doc["materials"] = {{{"pbrMetallicRoughness",
                          {{"baseColorFactor", {0.8, 0.8, 0.8, 1.0}},
                           {"metallicFactor", 0.0},
                           {"roughnessFactor", 0.8}}}}};
    doc["meshes"] = {
        {{"primitives",
          {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"indices", 4}, {"material", 0}}}}},
        {{"primitives",
          {{{"attributes", {{"POSITION", 2}, {"NORMAL", 3}}}, {"indices", 5}, {"material", 0}}}}}};
    return writeGltf(name, doc, f, indices);
}

} // namespace

// The shadow map's failure that ray-traced sun shadows fix: resolution over a large scene. The
// sun's one whole-scene map spreads 2048 texels over the scene; on a 400 m floor a 4 cm post's
// shadow falls between its texels and is lost, where the same map over a 40 m floor resolves it.
// Traced shadows do not depend on the scene's size: the big floor with RT shows the shadow the
// small floor's map shows, and sharper. (The other classic failure, contact gaps from the map's
// depth bias, is also absent: a ray leaves the receiver itself.)
TEST(RayTracing, SunShadowsKeepAThinCastersShadowTheWholeSceneMapLoses) {
    SHADEL_REQUIRE(sharedGpu().device.optional.rayQuery,
                   "ray query (VK_KHR_ray_query) on the device");
    auto options = [](const std::string& scene, RenderMode mode, bool traced) {
        RenderOptions o = renderOptions(scene, mode, 320, 180);
        o.progress = false;
        o.rt.shadows = traced;
        // The same shading rate with and without tracing (traced terms keep the full rate,
        // render/shadel/material_rate.h), so the renders differ only in their shadows.
        o.materialRate = false;
        return o;
    };
    std::string big = thinPostScene("thin_post_400m", 400.0f);
    std::string small = thinPostScene("thin_post_40m", 40.0f);
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        SCOPED_TRACE(mode == RenderMode::Forward ? "forward" : "decoupled");
        RenderRun bigMap = renderChecked(options(big, mode, false));
        RenderRun bigTraced = renderChecked(options(big, mode, true));
        RenderRun smallMap = renderChecked(options(small, mode, false));
        // The post's shadow: where each render is darker than the big floor's map render.
        ShadowPixels resolved = shadowPixels(smallMap, bigMap, 8.0);
        ShadowPixels traced = shadowPixels(bigTraced, bigMap, 8.0);
        size_t agree = 0;
        for (size_t i : traced.darker)
            agree += std::find(resolved.darker.begin(), resolved.darker.end(), i) !=
                     resolved.darker.end();
        std::printf("thin post's shadow: %zu pixels with the 40 m map, %zu traced on the 400 m "
                    "floor (%zu of them in the map's), 400 m map vs traced %.2f dB\n",
                    resolved.darker.size(), traced.darker.size(), agree,
                    psnr(bigMap.frames.back().rgba, bigTraced.frames.back().rgba));
        EXPECT_GE(resolved.darker.size(), 60u) << "the 40 m map should show the post's shadow";
        EXPECT_GE(double(traced.darker.size()), 0.5 * double(resolved.darker.size()));
        EXPECT_GE(double(agree), 0.75 * double(traced.darker.size())) << "not where the map's is";
        EXPECT_EQ(traced.brighter, 0u) << "tracing only takes away light the map let through";
    }
}

// builtin:lights: 16 shadow-casting spots over posts. --rt-shadows traces them (hard: one ray
// to the light; soft: --rt-shadow-rays over the lamp head) in place of their maps, in the
// shared lighting code, so both paths get them.
TEST(RayTracing, SpotShadowsAgreeWithTheSpotShadowMaps) {
    SHADEL_REQUIRE(sharedGpu().device.optional.rayQuery,
                   "ray query (VK_KHR_ray_query) on the device");
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        SCOPED_TRACE(mode == RenderMode::Forward ? "forward" : "decoupled");
        RenderOptions o = renderOptions("builtin:lights", mode, 192, 108);
        o.progress = false;
        RenderRun maps = renderChecked(o);
        o.spotShadows = false;
        RenderRun mapsOff = renderChecked(o);
        o.rt.shadows = true;
        RenderRun tracedOff = renderChecked(o); // the sun traced, no spot shadows at all
        o.spotShadows = true;
        RenderRun traced = renderChecked(o);
        EXPECT_EQ(traced.stats["rt"]["spot_shadows"].get<uint64_t>(), 16u);
        EXPECT_EQ(tracedOff.stats["rt"]["spot_shadows"].get<uint64_t>(), 0u);
        double db = psnr(traced.frames.back().rgba, maps.frames.back().rgba);
        // The occluders in the spots' cones (the posts) darken the street with RT on, and the
        // traced spot shadows only remove light.
        ShadowPixels rt = shadowPixels(traced, tracedOff, 8.0);
        ShadowPixels map = shadowPixels(maps, mapsOff, 2.0);
        size_t agree = 0;
        for (size_t i : rt.darker)
            agree += std::find(map.darker.begin(), map.darker.end(), i) != map.darker.end();
        std::printf("RT spot shadows vs maps: %.2f dB; %zu pixels darkened by the traced spot "
                    "shadows, %zu of them by the maps too\n",
                    db, rt.darker.size(), agree);
        EXPECT_GE(db, 30.0);
        EXPECT_GE(rt.darker.size(), 20u) << "no traced spot shadow darkened the street";
        EXPECT_EQ(rt.brighter, 0u) << "a traced shadow never adds light";
        EXPECT_GE(double(agree), 0.75 * double(rt.darker.size())) << "not where the maps' are";
        if (mode == RenderMode::Decoupled) break;
        // Soft: 4 jittered rays over the 0.4 m lamp heads; still the maps' shadows (PCSS on the
        // soft spots), and the penumbrae change the image.
        o.rt.shadowRays = 4;
        RenderRun soft = renderChecked(o);
        double softDb = psnr(soft.frames.back().rgba, maps.frames.back().rgba);
        std::printf("soft RT spot shadows vs maps: %.2f dB\n", softDb);
        EXPECT_GE(softDb, 30.0);
        EXPECT_LT(psnr(soft.frames.back().rgba, traced.frames.back().rgba), 99.0);
    }
}

namespace {

// assimp's simple_skin (a strip of two joints bending over 0..5.5 s) over a floor, lit by a low
// sun from the front, so the strip's shadow on the floor shows its pose. Written next to the
// test's other files: the floor's data in a .bin beside the .gltf.
std::string skinnedStripOverAFloor() {
    std::ifstream in("/usr/share/assimp/models/glTF2/simple_skin/simple_skin.gltf");
    nlohmann::json g = nlohmann::json::parse(in);
    const float pos[12] = {-3, 0, -4, 4, 0, -4, 4, 0, 3, -3, 0, 3};
    const float nrm[12] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
    const uint16_t idx[8] = {0, 2, 1, 0, 3, 2, 0, 0};
    std::string bin = tempPath("skin_floor.bin");
    std::ofstream out(bin, std::ios::binary);
    out.write(reinterpret_cast<const char*>(pos), sizeof(pos));
    out.write(reinterpret_cast<const char*>(nrm), sizeof(nrm));
    out.write(reinterpret_cast<const char*>(idx), sizeof(idx));
    out.close();
    size_t b = g["buffers"].size(), v = g["bufferViews"].size(), a = g["accessors"].size();
    g["buffers"].push_back(
        {{"byteLength", 112}, {"uri", std::filesystem::path(bin).filename().string()}});
    g["bufferViews"].push_back({{"buffer", b}, {"byteOffset", 0}, {"byteLength", 48}});
    g["bufferViews"].push_back({{"buffer", b}, {"byteOffset", 48}, {"byteLength", 48}});
    g["bufferViews"].push_back({{"buffer", b}, {"byteOffset", 96}, {"byteLength", 12}});
    g["accessors"].push_back({{"bufferView", v},
                              {"componentType", 5126},
                              {"count", 4},
                              {"type", "VEC3"},
                              {"min", {-3, 0, -4}},
                              {"max", {4, 0, 3}}});
    g["accessors"].push_back(
        {{"bufferView", v + 1}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}});
    g["accessors"].push_back(
        {{"bufferView", v + 2}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}});
    g["meshes"].push_back(
        {{"primitives",
          {{{"attributes", {{"POSITION", a}, {"NORMAL", a + 1}}}, {"indices", a + 2}}}}});
    g["nodes"].push_back({{"mesh", g["meshes"].size() - 1}});
    g["scenes"][0]["nodes"].push_back(g["nodes"].size() - 1);
    // The sun travels along (0.3, -0.6, -1): the node's rotation of -Z onto it.
    g["extensionsUsed"] = {"KHR_lights_punctual"};
    g["extensions"]["KHR_lights_punctual"]["lights"] = {
        {{"type", "directional"}, {"color", {1, 1, 1}}, {"intensity", 3.0}}};
    g["nodes"].push_back({{"rotation", {-0.26041905, -0.13020952, 0.0, 0.95667518}},
                          {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    g["scenes"][0]["nodes"].push_back(g["nodes"].size() - 1);
    std::string path = tempPath("skin_floor.gltf");
    std::ofstream(path) << g.dump();
    return path;
}

} // namespace

// Animated BLASes: the GPU-skinned strip's BLAS is refit to each frame's pose (--time-step), so
// its traced shadow on the floor is the shadow map's at every time; the bind pose's static BLAS
// (--rt-animated-blas off) casts the wrong one.
TEST(RayTracing, SkinnedBlasRefitsFollowThePose) {
    SHADEL_REQUIRE(sharedGpu().device.optional.rayQuery,
                   "ray query (VK_KHR_ray_query) on the device");
    std::string scene = skinnedStripOverAFloor();
    // The shadel path too: its RT cache restarts every history when playback reposes anything.
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        SCOPED_TRACE(mode == RenderMode::Forward ? "forward" : "decoupled");
        RenderOptions o = renderOptions(scene, mode, 160, 90);
        o.progress = false;
        o.cameraOverrides.from = glm::vec3(0.5f, 3.0f, 5.0f);
        o.cameraOverrides.lookAt = glm::vec3(0.5f, 0.7f, -1.0f);
        o.frames = 3;
        o.time = 0.2; // frames at 0.2, 0.6 and 1.0 s: three poses
        o.timeStep = 0.4;
        RenderRun maps = renderChecked(o);
        o.rt.shadows = true;
        RenderRun refit = renderChecked(o);
        o.rt.animatedBlas = false;
        RenderRun bindPose = renderChecked(o);
        const auto& s = refit.stats;
        EXPECT_EQ(s["rt"]["animated_blases"].get<uint64_t>(), 1u);
        // Near the camera every changed pose is an update: the first a build, then refits.
        EXPECT_EQ(s["blas_rebuilds"].get<uint64_t>(), 1u);
        EXPECT_EQ(s["blas_refits"].get<uint64_t>(), 2u);
        EXPECT_EQ(bindPose.stats["blas_refits"].get<uint64_t>(), 0u);
        for (size_t f : {1, 2}) {
            double db = psnr(refit.frames[f].rgba, maps.frames[f].rgba);
            double stale = psnr(bindPose.frames[f].rgba, maps.frames[f].rgba);
            std::printf(
                "t = %.1f s: refit RT shadows vs shadow map %.2f dB (bind-pose BLAS %.2f dB)\n",
                0.2 + 0.4 * double(f), db, stale);
            EXPECT_GE(db, 30.0);
            EXPECT_GT(db, stale + 5.0)
                << "the refit BLAS casts no better shadow than the bind pose's";
        }
        double poses = psnr(refit.frames[1].rgba, refit.frames[2].rgba);
        std::printf("t = 0.6 s vs 1.0 s: %.2f dB\n", poses);
        EXPECT_LT(poses, 40.0) << "the two times' images do not differ";
    }
}

// The refit schedule: near the camera every changed pose is an update, every 9th a build (after
// 8 refits); 60 m away (beyond 16 m: at most one update per ceil(60 / 16) = 4 frames) fewer.
TEST(RayTracing, SkinnedBlasRebuildsAfterEightRefitsAndFarOnesUpdateLessOften) {
    SHADEL_REQUIRE(sharedGpu().device.optional.rayQuery,
                   "ray query (VK_KHR_ray_query) on the device");
    RenderOptions o = renderOptions("/usr/share/assimp/models/glTF2/simple_skin/simple_skin.gltf",
                                    RenderMode::Forward, 64, 36);
    o.progress = false;
    o.cameraOverrides.lookAt = glm::vec3(0.5f, 1.0f, 0.0f);
    o.frames = 10;
    o.time = 0.0;
    o.timeStep = 0.1; // a new pose every frame
    o.rt.shadows = true;
    o.cameraOverrides.from = glm::vec3(0.5f, 1.0f, 4.0f);
    RenderRun near = renderChecked(o);
    o.cameraOverrides.from = glm::vec3(0.5f, 1.0f, 60.0f);
    RenderRun far = renderChecked(o);
    // Frames 0 and 9 build, 1..8 refit.
    EXPECT_EQ(near.stats["blas_refits"].get<uint64_t>(), 8u);
    EXPECT_EQ(near.stats["blas_rebuilds"].get<uint64_t>(), 2u);
    // Frames 0 (build), 4 and 8 (refits).
    EXPECT_EQ(far.stats["blas_refits"].get<uint64_t>(), 2u);
    EXPECT_EQ(far.stats["blas_rebuilds"].get<uint64_t>(), 1u);
}
