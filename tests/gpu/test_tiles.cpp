// Seed 004's screen-space passes over classified 8x8 tiles (render/screenspace, render/tiles):
// classification must change nothing, the classes must reflect the scene, and the passes must
// do something.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>

#include "gpu_test_env.h"
#include "scene_files.h"

using namespace shadel;
using namespace shadel::test;

namespace {

RenderOptions arena(RenderMode mode, bool screenSpace, bool classification, uint32_t w = 320,
                    uint32_t h = 180) {
    RenderOptions o = renderOptions("builtin:arena", mode, w, h);
    o.screenSpace = screenSpace;
    o.tileClassification = classification;
    o.progress = false;
    return o;
}

} // namespace

// Classifying tiles is an optimisation only: each pass computes the same
// value per pixel whether it runs on its list or on every tile.
TEST(Tiles, ClassificationOnMatchesOffForward) {
    RenderRun on = renderChecked(arena(RenderMode::Forward, true, true));
    RenderRun off = renderChecked(arena(RenderMode::Forward, true, false));
    double p = psnr(on.frames[0].rgba, off.frames[0].rgba);
    std::printf("arena 320x180 forward: classification on vs off %.2f dB\n", p);
    EXPECT_GE(p, 50.0);

    // The classes: every tile is sky or has a surface; the arena shows sky, smooth surfaces
    // (stage, water), rough ones only, and skin, and none of them covers the whole screen.
    const auto& c = on.stats["tile_classes"];
    uint32_t tiles = c["tiles"];
    EXPECT_EQ(tiles, 40u * 23u);
    EXPECT_EQ(uint32_t(c["sky"]) + uint32_t(c["surface"]), tiles);
    EXPECT_EQ(uint32_t(c["ssr"]) + uint32_t(c["ssr_clear"]), uint32_t(c["surface"]));
    for (const char* k : {"sky", "sky_edge", "ssr", "ssr_clear", "sss"}) {
        EXPECT_GT(uint32_t(c[k]), 0u) << k;
        EXPECT_LT(uint32_t(c[k]), tiles) << k;
    }
    EXPECT_LE(uint32_t(c["sky_edge"]), uint32_t(c["surface"]));
    EXPECT_LE(uint32_t(c["sss"]), uint32_t(c["surface"]));
    // Off: no classification ran, so no counts.
    EXPECT_FALSE(off.stats["tile_classes"].contains("sky"));
}

// The passes change the image (sky gradient, reflections, scattering) but not everywhere:
// screen space on vs off differs, and covered pixels stay covered.
TEST(Tiles, ScreenSpacePassesChangeTheImage) {
    RenderRun on = renderChecked(arena(RenderMode::Forward, true, true));
    RenderRun plain = renderChecked(arena(RenderMode::Forward, false, true));
    double p = psnr(on.frames[0].rgba, plain.frames[0].rgba);
    std::printf("arena 320x180: screen-space on vs off %.2f dB\n", p);
    EXPECT_LT(p, 45.0);
    EXPECT_GT(p, 15.0);
    EXPECT_EQ(on.frames[0].pixelsCovered, plain.frames[0].pixelsCovered);
    EXPECT_FALSE(plain.stats.contains("tile_classes"));
}

// The decoupled path draws the same G-buffer from its camera lists; classification holds there.
TEST(Tiles, ClassificationOnMatchesOffDecoupled) {
    RenderRun on = renderChecked(arena(RenderMode::Decoupled, true, true, 192, 108));
    RenderRun off = renderChecked(arena(RenderMode::Decoupled, true, false, 192, 108));
    double p = psnr(on.frames[0].rgba, off.frames[0].rgba);
    std::printf("arena 192x108 decoupled: classification on vs off %.2f dB\n", p);
    EXPECT_GE(p, 50.0);
}

TEST(Tiles, VisualizeTilesTintsTheImage) {
    RenderOptions o = arena(RenderMode::Forward, true, true);
    RenderRun plain = renderChecked(o);
    o.visualize = Visualize::Tiles;
    RenderRun tinted = renderChecked(o);
    EXPECT_LT(psnr(plain.frames[0].rgba, tinted.frames[0].rgba), 30.0);
}

TEST(Tiles, BadFlagsAreOneLineAndExitCode2) {
    for (const std::string args :
         {"render --size 16x16 --tile-classification maybe", "render --size 16x16 --screen-space 2",
          "render --size 16x16 --visualize tiles",
          "render --size 16x16 --mode decoupled --marking visibility --screen-space on"}) {
        std::string err;
        EXPECT_EQ(runShadel("", args, err), 2) << args << ": " << err;
        EXPECT_EQ(err.rfind("shadel: ", 0), 0u) << args << ": " << err;
        EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << args << ": " << err;
    }
}

// Distance-field shadows agree with the shadow map where both exist (sun-facing surfaces), on
// a scene the 2048² shadow map resolves well (builtin:smooth: 4 cm texels); the distance-field
// AO leaves open ground nearly unoccluded and darkens contact. The fields come from the cache
// on a second run, identical.
TEST(DistanceFields, ShadowsAgreeWithTheShadowMap) {
    RenderOptions o = renderOptions("builtin:smooth", RenderMode::Forward, 320, 180);
    o.screenSpace = true;
    o.distanceFieldLighting = true;
    o.progress = false;
    RenderRun run = renderChecked(o);
    const auto& df = run.stats["distance_fields"];
    std::printf("smooth 320x180: DF shadows vs shadow map %.2f dB over %llu pixels, mean AO %.3f\n",
                double(df["shadow_vs_shadow_map_db"]),
                (unsigned long long)uint64_t(df["overlap_pixels"]), double(df["mean_ao"]));
    EXPECT_EQ(uint32_t(df["meshes_in_atlas"]), uint32_t(df["meshes"]));
    EXPECT_GT(uint32_t(df["instances"]), 10u);
    EXPECT_GT(uint64_t(df["overlap_pixels"]), 20000u);
    EXPECT_GE(double(df["shadow_vs_shadow_map_db"]), 30.0);
    EXPECT_LT(double(df["mean_ao"]), 0.99);
    EXPECT_GT(double(df["mean_ao"]), 0.85);
    // Applied (AO): the image differs from the same frame without fields.
    o.distanceFieldLighting = false;
    RenderRun plain = renderChecked(o);
    EXPECT_LT(psnr(run.frames[0].rgba, plain.frames[0].rgba), 45.0);
}

TEST(DistanceFields, NeedScreenSpace) {
    std::string err;
    EXPECT_EQ(runShadel("", "render --size 16x16 --distance-fields on", err), 2) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_EQ(runShadel("", "render --size 16x16 --distance-fields yes", err), 2) << err;
}
