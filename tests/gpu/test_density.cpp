// View-driven density, the runtime half: shadels where the screen needs them (view-driven density
// per mesh, world chunks), a prefiltered material in shadel space and anisotropic MIP selection,
// judged at the sizes users run (docs/design.md, how correctness is judged), not only at one small
// size.
#include "gpu_test_env.h"

#include <cmath>

#include "render/view_density.h"
#include "scene/load.h"

using namespace shadel;
using namespace shadel::test;

namespace {

double stat(const RenderRun& run, const char* name) {
    return run.stats[name].get<double>();
}

} // namespace

// The one-texel checker against an 8x8 supersampled forward render: decoupled must beat 1x
// forward by 2 dB at every size (1920x1080 is measured with the CLI: too slow for CI here).
TEST(Density, CheckerBeatsForwardByTwoDecibelsAtEverySize) {
    const uint32_t sizes[][2] = {{192, 108}, {480, 270}, {960, 540}};
    for (const auto& size : sizes) {
        RenderOptions ref = renderOptions("builtin:checker", RenderMode::Forward, size[0], size[1]);
        ref.ssaa = 8;
        RenderRun reference = renderChecked(ref);
        RenderRun fwd =
            renderChecked(renderOptions("builtin:checker", RenderMode::Forward, size[0], size[1]));
        RenderRun dec = renderChecked(
            renderOptions("builtin:checker", RenderMode::Decoupled, size[0], size[1]));
        double pf = psnr(fwd.frames[0].rgba, reference.frames[0].rgba);
        double pd = psnr(dec.frames[0].rgba, reference.frames[0].rgba);
        std::printf("[ figures ] checker %ux%u vs 8x8 SSAA: forward %.2f dB, decoupled %.2f dB "
                    "(%+.2f), %.2f shadels/pixel\n",
                    size[0], size[1], pf, pd, pd - pf, stat(dec, "shadels_per_pixel"));
        EXPECT_GE(pd, pf + 2.0) << size[0] << "x" << size[1];
        EXPECT_EQ(dec.stats["reconstruction_misses"].get<uint64_t>(), 0u);
        // Both modes draw the same chunked scene: identical coverage.
        EXPECT_EQ(dec.stats["pixels_covered"], fwd.stats["pixels_covered"]);
        EXPECT_GT(dec.stats["view_density"]["chunks"].get<uint64_t>(), 1u);
        if (size[0] == 480) {
            // Without the prefilter (one material sample per shadel) the far field aliases.
            RenderOptions one = renderOptions("builtin:checker", RenderMode::Decoupled, 480, 270);
            one.materialSamples = 1;
            double p1 = psnr(renderChecked(one).frames[0].rgba, reference.frames[0].rgba);
            std::printf("[ figures ] checker 480x270, 1 material sample: %.2f dB\n", p1);
            EXPECT_GT(pd, p1 + 0.5);
        }
    }
}

// At 1280x720: 1.0 .. 2.5 shadels per covered pixel and (almost) no pixel whose MIP-0 shadel is
// larger than the pixel. One global density (the old default) fails the second on the checker.
// The density is judged at the full shading rate: the material rate (render/shadel/
// material_rate.h) then shades plain rough materials up to a MIP coarser on purpose, which
// lowers the first figure (builtin:default 0.74) but cannot magnify (it only coarsens).
TEST(Density, ShadelsPerPixelAndMagnificationAt720p) {
    for (const std::string scene : {"builtin:default", "builtin:checker"}) {
        RenderOptions o = renderOptions(scene, RenderMode::Decoupled, 1280, 720);
        o.materialRate = false;
        RenderRun run = renderChecked(o);
        double perPixel = stat(run, "shadels_per_pixel");
        double magnified = stat(run, "magnified_pixel_fraction");
        std::printf("[ figures ] %s 1280x720: %.2f shadels/pixel, magnified pixel fraction %.4f, "
                    "%llu MIP-0 shadels baked in %.2f s\n",
                    scene.c_str(), perPixel, magnified,
                    (unsigned long long)run.stats["mip0_shadels"].get<uint64_t>(),
                    stat(run, "bake_seconds"));
        EXPECT_GE(perPixel, 1.0) << scene;
        EXPECT_LE(perPixel, 2.5) << scene;
        EXPECT_LT(magnified, 0.05) << scene;
        EXPECT_EQ(run.stats["reconstruction_misses"].get<uint64_t>(), 0u) << scene;
        EXPECT_EQ(run.stats["chunks_overflowed"].get<uint64_t>(), 0u) << scene;
    }
    RenderOptions global = renderOptions("builtin:checker", RenderMode::Decoupled, 1280, 720);
    global.shadelsPerMetre = 32.0f;
    EXPECT_GT(stat(renderChecked(global), "magnified_pixel_fraction"), 0.3);
}

TEST(Density, FlickersFarLessThanForwardAt480x270) {
    RenderOptions o = renderOptions("builtin:default", RenderMode::Forward, 480, 270);
    o.frames = 16;
    o.jitter = true;
    RenderRun fwd = renderChecked(o);
    o.mode = RenderMode::Decoupled;
    RenderRun dec = renderChecked(o);
    double ff = meanFrameDelta(fwd), fd = meanFrameDelta(dec);
    std::printf("[ figures ] default 480x270, 16 jittered frames: mean |frame delta| forward %.3f, "
                "decoupled %.3f (ratio %.3f)\n",
                ff, fd, fd / ff);
    EXPECT_GT(ff, 0.0);
    EXPECT_LE(fd, ff / 3.0);
    EXPECT_EQ(dec.stats["reconstruction_misses"].get<uint64_t>(), 0u);
}

// Over budget every density is scaled down by one factor, reported in the stats; the frame
// stays correct (coarser, more magnified).
TEST(Density, BudgetScalesEveryDensityDown) {
    RenderOptions o = renderOptions("builtin:checker", RenderMode::Decoupled, 480, 270);
    RenderRun roomy = renderChecked(o);
    o.shadelBudget = 2e5;
    RenderRun tight = renderChecked(o);
    double scale = tight.stats["view_density"]["budget_scale"].get<double>();
    std::printf("[ figures ] checker 480x270 within 0.2M MIP-0 shadels: densities x%.3f, "
                "magnified %.3f (unconstrained %.3f)\n",
                scale, stat(tight, "magnified_pixel_fraction"),
                stat(roomy, "magnified_pixel_fraction"));
    EXPECT_EQ(roomy.stats["view_density"]["budget_scale"].get<double>(), 1.0);
    EXPECT_LT(scale, 1.0);
    EXPECT_LT(tight.stats["mip0_shadels"].get<uint64_t>(),
              roomy.stats["mip0_shadels"].get<uint64_t>());
    EXPECT_GT(stat(tight, "magnified_pixel_fraction"), stat(roomy, "magnified_pixel_fraction"));
    EXPECT_EQ(tight.stats["reconstruction_misses"].get<uint64_t>(), 0u);
}

// The distance density is chosen from: exact for simple cases, frustum-aware, over every frame.
TEST(Density, NearestVisibleDistanceSeesOnlyWhatTheFrustumShows) {
    Camera c;
    c.position = {0, 0, 0};
    c.forward = {0, 0, -1};
    c.yfov = 0.8f, c.znear = 0.1f, c.zfar = 100.0f;
    CameraView v = makeCameraView(c, 160, 90);
    Aabb ahead{{-1, -1, -11}, {1, 1, -10}};
    EXPECT_NEAR(nearestVisibleDistance(v, ahead), 10.0f, 1e-3f);
    Aabb behind{{-1, -1, 10}, {1, 1, 11}};
    EXPECT_EQ(nearestVisibleDistance(v, behind), kNotVisible);
    // A ground plane 1.5 m below: the nearest *visible* point is where the bottom of the view
    // meets it, not the point right under the camera.
    Aabb ground{{-100, -1.5f, -100}, {100, -1.5f, 100}};
    float d = nearestVisibleDistance(v, ground);
    float expected = 1.5f / std::sin(0.4f); // straight ahead, the view's lower edge
    EXPECT_GT(d, 1.5f * 1.5f);
    EXPECT_NEAR(d, expected, 0.05f * expected);
    // Every frame of a path counts: an orbit ending next to a box sees it nearer.
    Scene scene = loadScene("builtin:smooth");
    Camera start = findCamera(scene, "");
    RunViews still = runViews(start, CameraPath::Static, 8, scene.worldBounds(), 160, 90);
    RunViews walk = runViews(start, CameraPath::Walk, 8, scene.worldBounds(), 160, 90);
    EXPECT_EQ(walk.views.size(), 8u);
    Aabb target =
        transformAabb(scene.meshes[scene.instances[1].mesh].bounds, scene.instances[1].transform);
    EXPECT_LE(nearestVisibleDistance(walk, target), nearestVisibleDistance(still, target));
}

// Quantised densities and grid-aligned chunks: a camera moved by a few centimetres bakes the
// same meshes at the same densities (bake-cache hits); a camera twice as far bakes coarser.
TEST(Density, NearbyCamerasChooseTheSameChunksAndDensities) {
    Scene scene = loadScene("builtin:checker");
    Camera a = findCamera(scene, "");
    Camera b = a;
    b.position += glm::vec3(0.03f, 0.0f, -0.02f);
    Camera far = a;
    far.position.y *= 2.0f;
    auto density = [&](const Camera& c) {
        RunViews v = runViews(c, CameraPath::Static, 1, scene.worldBounds(), 480, 270);
        return viewDrivenDensity(scene, v, ViewDensityOptions{});
    };
    ViewDensity da = density(a), db = density(b), dfar = density(far);
    ASSERT_EQ(da.scene.meshes.size(), db.scene.meshes.size());
    EXPECT_GT(da.scene.meshes.size(), 1u);
    EXPECT_EQ(da.meshDensity, db.meshDensity);
    for (size_t i = 0; i < da.scene.meshes.size(); ++i)
        EXPECT_EQ(da.scene.meshes[i].indices, db.scene.meshes[i].indices) << i;
    EXPECT_LT(dfar.maxDensityWorld, da.maxDensityWorld);
    for (float d : da.meshDensity) // powers of 2^(1/4)
        EXPECT_NEAR(std::log2(d) * 4.0f, std::round(std::log2(d) * 4.0f), 1e-3f) << d;
}

// Only the instances seen close enough take a mesh's chunks; the rest of the instances sharing
// the mesh keep it whole. builtin:many's buildings share three meshes: splitting all of them for
// the few next to the street multiplied a million instances by the chunk count (24M instances,
// a 3.9 GB instance buffer).
TEST(Density, OnlyInstancesSeenCloseTakeTheChunks) {
    BuiltinSceneOptions options;
    options.instances = 20000;
    Scene scene = loadScene("builtin:many", {}, options);
    Camera start = findCamera(scene, "");
    RunViews views = runViews(start, CameraPath::Orbit, 24, scene.worldBounds(), 320, 180);
    ViewDensity d = viewDrivenDensity(scene, views, ViewDensityOptions{});
    ASSERT_GT(d.meshesSplit, 0u); // the ground and the buildings by the street are split
    size_t added = d.scene.instances.size() - scene.instances.size();
    EXPECT_LT(added, 2000u) << "chunks of instances nobody sees close";
    // Every instance is still drawn: the whole mesh or all of its chunks, same transform.
    size_t whole = 0;
    for (const Instance& inst : d.scene.instances)
        whole += d.scene.meshes[inst.mesh].name.find(" chunk ") == std::string::npos;
    EXPECT_GT(whole, scene.instances.size() * 9 / 10);
    // The chunks of a split instance cover the same triangles as the mesh it replaces.
    auto area = [](const Mesh& m) {
        double a = 0;
        for (size_t i = 0; i + 2 < m.indices.size(); i += 3)
            a += 0.5 *
                 glm::length(glm::cross(
                     m.vertices[m.indices[i + 1]].position - m.vertices[m.indices[i]].position,
                     m.vertices[m.indices[i + 2]].position - m.vertices[m.indices[i]].position));
        return a;
    };
    double original = 0, drawn = 0;
    for (const Instance& inst : scene.instances) original += area(scene.meshes[inst.mesh]);
    for (const Instance& inst : d.scene.instances) drawn += area(d.scene.meshes[inst.mesh]);
    EXPECT_NEAR(drawn, original, 1e-4 * original);
}
