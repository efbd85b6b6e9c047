// Seed 004's screen-space passes over classified 8x8 tiles (render/screenspace, render/tiles):
// classification must change nothing, the classes must reflect the scene, and the passes must
// do something.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>

#include <algorithm>

#include "gpu_test_env.h"

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

int runShadel(const std::string& args, std::string& err) {
    std::string errFile =
        (std::filesystem::temp_directory_path() / "shadel_tiles_stderr.txt").string();
    std::string cmd =
        std::string("timeout 120 ") + SHADEL_BINARY + " " + args + " >/dev/null 2>" + errFile;
    int status = std::system(cmd.c_str());
    std::ifstream in(errFile);
    std::stringstream ss;
    ss << in.rdbuf();
    err = ss.str();
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

} // namespace

// The seed's claim: classifying tiles is an optimisation only. Each pass computes the same
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
        EXPECT_EQ(runShadel(args, err), 2) << args << ": " << err;
        EXPECT_EQ(err.rfind("shadel: ", 0), 0u) << args << ": " << err;
        EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << args << ": " << err;
    }
}
