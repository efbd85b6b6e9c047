// The sun's shadow map kept across frames (render/lighting/sun_shadow_cache.h): drawn once from
// every caster in the sun's volume while the sun, the casters and their LODs stay put, the same
// image as redrawing it every frame from the casters whose shadow can reach the view.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "gpu_test_env.h"

using namespace shadel;
using namespace shadel::test;

namespace {

uint32_t sunMapDraws(const RenderRun& run) {
    return run.stats["sun_shadow_map_draws"].get<uint32_t>();
}

} // namespace

// A moving camera over a still scene: one draw, and the kept map holds more casters than a
// camera-culled one (the town beyond the view). Forward: every frame the image of a map redrawn
// each frame. Decoupled: a chunk at the screen's edge has shadels beyond it, lit at points whose
// casters the camera-culled map may leave out (their shadow cannot reach the view); the kept
// map holds them, so a few edge pixels of such chunks differ (measured at 192x108: frames 1 and
// 2 of 4, 25 and 2 pixels within 16 of the left edge, worst 55.4 dB).
TEST(SunShadowCache, KeptMapDrawsOnceWithTheImageOfARedrawnOne) {
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        RenderOptions o = renderOptions("builtin:default", mode, 192, 108);
        o.progress = false;
        o.frames = 4;
        o.cameraPath = CameraPath::Orbit;
        RenderRun kept = renderChecked(o);
        o.sunShadowCache = false;
        RenderRun redrawn = renderChecked(o);
        const char* name = mode == RenderMode::Forward ? "forward" : "decoupled";
        EXPECT_EQ(kept.stats["sun_shadow_cache"], "on");
        EXPECT_EQ(redrawn.stats["sun_shadow_cache"], "off");
        EXPECT_EQ(sunMapDraws(kept), 1u) << name;
        EXPECT_EQ(sunMapDraws(redrawn), 4u) << name;
        // The first frame's list, the one the kept map was drawn from (later frames build the
        // camera-culled list for the other readers of the sun's list and draw no map).
        o.frames = 1;
        RenderRun first = renderChecked(o);
        o.sunShadowCache = true;
        RenderRun firstKept = renderChecked(o);
        uint32_t keptCasters = firstKept.stats["culling"]["views"]["shadow"]["instances_drawn"];
        uint32_t viewCasters = first.stats["culling"]["views"]["shadow"]["instances_drawn"];
        double worst = worstFramePsnr(kept, redrawn);
        std::printf("[ figures ] builtin:default 192x108 orbit, %s: sun map draws %u (kept) / %u, "
                    "casters %u / %u, worst frame %.2f dB\n",
                    name, sunMapDraws(kept), sunMapDraws(redrawn), keptCasters, viewCasters, worst);
        EXPECT_GT(keptCasters, viewCasters) << name << ": every caster in the sun's volume";
        // Frames that keep the map build no sun list (nothing else draws it here).
        EXPECT_EQ(kept.stats["culling"]["views"]["shadow"]["instances_drawn"], 0) << name;
        ASSERT_EQ(kept.frames.size(), redrawn.frames.size());
        if (mode == RenderMode::Forward) {
            for (size_t i = 0; i < kept.frames.size(); ++i)
                EXPECT_EQ(kept.frames[i].rgba, redrawn.frames[i].rgba) << "frame " << i;
        } else {
            EXPECT_GE(worst, 50.0);
        }
    }
}

// Where the sun's list follows the camera the map cannot be kept: --lod on picks the casters'
// LODs from the camera, with --shadow-culling whole-scene the spots and cascades draw the sun's
// camera-culled list, and with --gi lpv the reflective shadow maps do.
TEST(SunShadowCache, RedrawnWhereCastersFollowTheCamera) {
    RenderOptions o = renderOptions("builtin:default", RenderMode::Forward, 160, 90);
    o.progress = false;
    o.frames = 3;
    o.cameraPath = CameraPath::Orbit;
    o.lod = true;
    RenderRun lod = renderChecked(o);
    EXPECT_EQ(lod.stats["sun_shadow_cache"], "off");
    EXPECT_EQ(sunMapDraws(lod), 3u);
    o.lod = false;
    o.shadowCulling = ShadowCulling::WholeScene;
    RenderRun wholeScene = renderChecked(o);
    EXPECT_EQ(wholeScene.stats["sun_shadow_cache"], "off");
    EXPECT_EQ(sunMapDraws(wholeScene), 3u);
    o.shadowCulling = ShadowCulling::PerView;
    o.gi = GiMode::Lpv;
    RenderRun gi = renderChecked(o);
    EXPECT_EQ(gi.stats["sun_shadow_cache"], "off");
    EXPECT_EQ(sunMapDraws(gi), 3u);
}

// A value that is neither on nor off: one error line naming the flag, exit 2.
TEST(SunShadowCache, BadValueIsAnInputError) {
    std::string err = tempPath("sun_shadow_cache_stderr.txt");
    std::string cmd = std::string("timeout 120 ") + SHADEL_BINARY +
                      " render --scene builtin:default --size 64x36 --shadow-cache maybe --out " +
                      tempPath("sun_shadow_cache_bad.png") + " >/dev/null 2>" + err;
    int status = std::system(cmd.c_str());
    std::ifstream in(err);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    in.close();
    std::filesystem::remove(err);
    EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 2) << text;
    EXPECT_NE(text.find("--shadow-cache"), std::string::npos) << text;
}
