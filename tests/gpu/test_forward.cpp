#include "gpu_test_env.h"

#include "rhi/shader_messages.h"

using namespace shadel;
using namespace shadel::test;

TEST(Forward, RendersDefaultSceneWithCoverageAndTimings) {
    RenderOptions o;
    o.scene = "builtin:default";
    o.width = 160;
    o.height = 90;
    RenderRun run = renderChecked(o);
    ASSERT_EQ(run.frames.size(), 1u);
    const auto& s = run.stats;
    EXPECT_GT(s["pixels_covered"].get<uint64_t>(), 160u * 90u / 4)
        << "the default camera should see geometry";
    EXPECT_LE(s["pixels_covered"].get<uint64_t>(), 160u * 90u);
    std::vector<std::string> passes;
    for (auto& p : s["passes"]) passes.push_back(p["name"]);
    // The default scene's few lights are culled per subgroup in shading (render/lighting/
    // light_culling.cpp, subgroupListsFit): lightCulling only clears the counters. Nothing
    // draws after forward shading, so the tonemap is fused into it (render/post/tonemap.h).
    EXPECT_EQ(passes,
              (std::vector<std::string>{"instanceCull", "shadowMap", "depthPrepass", "lightCulling",
                                        "forwardShading", "displayReadback"}));
    // Every pass took time, and the passes ran inside the frame: their times (each measured
    // from its submit to its fence on lavapipe, between its timestamps on a GPU) sum to no
    // more than the frame's wall clock, which runs from the frame's start to the GPU finishing.
    double passesMs = 0.0, frameMs = s["frame_ms"]["median"].get<double>();
    for (auto& p : s["passes"]) {
        EXPECT_GT(p["gpu_ms"].get<double>(), 0.0) << p["name"];
        passesMs += p["gpu_ms"].get<double>();
    }
    EXPECT_LE(passesMs, frameMs) << "the passes took " << passesMs << " ms of a " << frameMs
                                 << " ms frame";
    // The image is not flat: sky and lit geometry differ.
    const auto& px = run.frames[0].rgba;
    int minL = 255, maxL = 0;
    for (size_t i = 0; i < px.size(); i += 4) {
        int l = (px[i] + px[i + 1] + px[i + 2]) / 3;
        minL = std::min(minL, l), maxL = std::max(maxL, l);
    }
    EXPECT_GT(maxL - minL, 60);
}

TEST(Forward, SameInputGivesSameImage) {
    RenderOptions o;
    o.scene = "builtin:smooth";
    o.width = 96;
    o.height = 64;
    o.frames = 2;
    RenderRun run = renderChecked(o);
    EXPECT_EQ(run.frames[0].rgba, run.frames[1].rgba) << "no jitter: frames must be identical";
}

TEST(Forward, JitterMovesTheImage) {
    RenderOptions o;
    o.scene = "builtin:checker";
    o.width = 96;
    o.height = 64;
    o.frames = 2;
    o.jitter = true;
    RenderRun run = renderChecked(o);
    EXPECT_NE(run.frames[0].rgba, run.frames[1].rgba);
}

TEST(Forward, SupersampledReferenceIsCloseToOneSampleOnSmoothContent) {
    RenderOptions o;
    o.scene = "builtin:smooth";
    o.width = 96;
    o.height = 64;
    RenderRun one = renderChecked(o);
    o.ssaa = 4;
    RenderRun four = renderChecked(o);
    double p = psnr(one.frames[0].rgba, four.frames[0].rgba);
    EXPECT_GT(p, 25.0) << "smooth content: 1x and 4x4 SSAA differ only on edges";
    EXPECT_LT(p, 99.0) << "SSAA must change edge pixels";
}

TEST(Forward, TimestampAndSubmitTimingGiveTheSamePasses) {
    RenderOptions o;
    o.scene = "builtin:smooth";
    o.width = 64;
    o.height = 64;
    o.timing = TimingMode::Timestamps;
    RenderRun a = renderChecked(o);
    o.timing = TimingMode::SubmitPerPass;
    RenderRun b = renderChecked(o);
    EXPECT_EQ(a.stats["passes"].size(), b.stats["passes"].size());
    EXPECT_EQ(a.frames[0].rgba, b.frames[0].rgba);
}

// The forward shading draws opaque surfaces in three lists by material class: plain materials
// by a pipeline with the material features compiled out, textures-only materials by one with
// only textures, the others (procedurals, clear coat, sheen) by the all-features one
// (render/forward). builtin:default has plain walls and procedural checker and bricks on
// screen, builtin:textures textured materials; a class whose list went undrawn, or was drawn
// with a pipeline lacking its features, would leave sky or a flat base colour where the
// tile-shaded forward path (one all-features permutation per 16x16 tile, the same shared
// material and lighting code) shades the surface.
TEST(Forward, MaterialClassListsShadeAsTheAllFeaturesShader) {
    // Measured: 47.3 dB (default: the two paths' derivatives differ at triangle edges) and
    // 82.7 dB (textures); a class shaded without its features falls far below (17.9 dB).
    for (const char* scene : {"builtin:default", "builtin:textures"}) {
        RenderOptions o = renderOptions(scene, RenderMode::Forward, 160, 90);
        RenderRun raster = renderChecked(o);
        o.spectra = Spectra::Single;
        RenderRun tiled = renderChecked(o);
        uint64_t tiles = tiled.stats["light_tiles"].get<uint64_t>();
        uint64_t featuredTiles = tiled.stats["tile_features"].value("material", uint64_t(0));
        EXPECT_GT(featuredTiles, 0u) << scene << ": no material with features on screen";
        EXPECT_LT(featuredTiles, tiles) << scene << ": no tile without one";
        EXPECT_GE(psnr(raster.frames[0].rgba, tiled.frames[0].rgba), 45.0) << scene;
    }
}
