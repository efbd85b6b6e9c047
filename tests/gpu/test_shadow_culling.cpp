// Per-view shadow culling (render/culling/culling.h): the instanceCull dispatch that
// fills the camera's and the sun's lists also culls every instance against each sun cascade's
// box and each shadow-casting spot's frustum, so a spot or cascade draws only its own casters,
// where --shadow-culling whole-scene draws every caster of the scene for each of them. The maps
// hold the same depths either way: the images must not change.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>

#include "gpu_test_env.h"

using namespace shadel;
using namespace shadel::test;

namespace {
RenderOptions shadowCullingOptions(RenderMode mode, ShadowCulling culling) {
    RenderOptions o = renderOptions("builtin:lights", mode, 192, 108);
    o.sunCascades = 4;
    o.shadowCulling = culling;
    // The sun's list as each culling mode builds it for one camera: a kept sun map
    // (render/lighting/sun_shadow_cache.h, per-view only) takes every caster in its volume.
    o.sunShadowCache = false;
    o.progress = false;
    return o;
}

uint32_t drawn(const RenderRun& run, const std::string& view) {
    const auto& views = run.stats["culling"]["views"];
    EXPECT_TRUE(views.contains(view)) << view << " missing from " << views.dump();
    return views.contains(view) ? views[view]["instances_drawn"].get<uint32_t>() : 0u;
}

uint32_t cullingDispatches(const RenderRun& run) {
    return run.stats["culling"]["dispatches"].get<uint32_t>();
}

size_t cullingPasses(const RenderRun& run) {
    size_t n = 0;
    for (const auto& p : run.stats["passes"])
        n += p["name"].get<std::string>().rfind("instanceCull", 0) == 0;
    return n;
}
} // namespace

TEST(ShadowCulling, SpotsAndCascadesDrawTheirOwnCastersSameImageForward) {
    RenderRun perView =
        renderChecked(shadowCullingOptions(RenderMode::Forward, ShadowCulling::PerView));
    RenderRun wholeScene =
        renderChecked(shadowCullingOptions(RenderMode::Forward, ShadowCulling::WholeScene));
    EXPECT_EQ(perView.stats["culling"]["shadow_culling"], "per-view");
    EXPECT_EQ(wholeScene.stats["culling"]["shadow_culling"], "whole-scene");
    uint32_t sun = drawn(wholeScene, "shadow");
    ASSERT_GT(sun, 50u) << "builtin:lights has many casters";
    EXPECT_EQ(drawn(perView, "shadow"), sun) << "the sun's whole-scene list is unchanged";
    EXPECT_EQ(drawn(perView, "camera"), drawn(wholeScene, "camera"));

    // Every shadowed spot sees a corner of the scene: its list is well below the whole scene's.
    uint32_t spots = 0, spotDrawn = 0;
    for (uint32_t i = 0; i < LIGHT_MAX_SPOT_SHADOWS; ++i) {
        std::string view = "spot_shadow_" + std::to_string(i);
        if (!wholeScene.stats["culling"]["views"].contains(view)) continue;
        spots++;
        uint32_t own = drawn(perView, view);
        EXPECT_EQ(drawn(wholeScene, view), sun) << view << ": whole-scene draws the sun's list";
        EXPECT_LE(own * 4, sun) << view;
        spotDrawn += own;
    }
    ASSERT_GE(spots, 8u) << "builtin:lights has shadowed spots";

    // Cascades: nearer slices are smaller boxes, so they hold fewer casters; the last covers
    // the far street (every caster the sun's list has there at most).
    uint32_t cascade[4];
    for (uint32_t i = 0; i < 4; ++i) {
        cascade[i] = drawn(perView, "sun_cascade_" + std::to_string(i));
        EXPECT_EQ(drawn(wholeScene, "sun_cascade_" + std::to_string(i)), sun);
        EXPECT_LE(cascade[i], sun);
        if (i > 0) {
            EXPECT_LE(cascade[i - 1], cascade[i]) << "cascade " << i;
        }
    }
    EXPECT_LT(cascade[0] * 4, cascade[3]) << "the nearest cascade holds far fewer casters";

    double p = psnr(perView.frames[0].rgba, wholeScene.frames[0].rgba);
    std::printf("[ figures ] builtin:lights 192x108 --sun-cascades 4: spots drew %u instances in "
                "total (%.1f avg over %u) vs %u each whole-scene; cascades %u/%u/%u/%u; "
                "per-view vs whole-scene %.2f dB\n",
                spotDrawn, double(spotDrawn) / spots, spots, sun, cascade[0], cascade[1],
                cascade[2], cascade[3], p);
    EXPECT_GE(p, 60.0);

    // One culling pass and dispatch for every view (the camera, the sun, 4 cascades, 16 spots).
    EXPECT_EQ(cullingPasses(perView), 1u);
    EXPECT_EQ(cullingDispatches(perView), 1u);
    EXPECT_EQ(cullingDispatches(wholeScene), 1u);
}

// Occlusion culling adds its phase-2 pass (camera only); the shadow views stay in the first
// dispatch with the lists they have without it, and the maps match whole-scene culling's.
TEST(ShadowCulling, OcclusionAddsOnlyTheCamerasSecondPhase) {
    RenderOptions o = shadowCullingOptions(RenderMode::Forward, ShadowCulling::PerView);
    RenderRun plain = renderChecked(o);
    o.occlusion = true;
    RenderRun occlusion = renderChecked(o);
    o.shadowCulling = ShadowCulling::WholeScene;
    RenderRun wholeScene = renderChecked(o);
    EXPECT_EQ(cullingPasses(occlusion), 2u);
    EXPECT_EQ(cullingDispatches(occlusion), 2u);
    for (const char* view : {"spot_shadow_0", "sun_cascade_0", "sun_cascade_3", "shadow"})
        EXPECT_EQ(drawn(occlusion, view), drawn(plain, view)) << view;
    EXPECT_GE(psnr(occlusion.frames[0].rgba, wholeScene.frames[0].rgba), 60.0);
}

// A spot's own list does not depend on the camera (without --lod): its map is drawn once while
// the camera orbits, where the sun's list (whole-scene) follows the camera and redraws it every
// frame. The last frames agree.
TEST(ShadowCulling, SpotMapsAreNotRedrawnForCameraMoves) {
    RenderOptions o = shadowCullingOptions(RenderMode::Forward, ShadowCulling::PerView);
    o.sunCascades = 1;
    o.frames = 3;
    o.cameraPath = CameraPath::Orbit;
    RenderRun perView = renderChecked(o);
    o.lod = true;
    RenderRun perViewLod = renderChecked(o);
    o.lod = false;
    o.shadowCulling = ShadowCulling::WholeScene;
    RenderRun wholeScene = renderChecked(o);
    EXPECT_EQ(perView.stats["spot_shadow_atlas_draws"], 1);
    EXPECT_EQ(perViewLod.stats["spot_shadow_atlas_draws"], 3) << "LODs follow the camera";
    EXPECT_EQ(wholeScene.stats["spot_shadow_atlas_draws"], 3);
    double p = psnr(perView.frames.back().rgba, wholeScene.frames.back().rgba);
    std::printf("[ figures ] orbit, last frame: per-view (maps drawn once) vs whole-scene (every "
                "frame) %.2f dB\n",
                p);
    EXPECT_GE(p, 60.0);
}

TEST(ShadowCulling, SameImageDecoupled) {
    RenderRun perView =
        renderChecked(shadowCullingOptions(RenderMode::Decoupled, ShadowCulling::PerView));
    RenderRun wholeScene =
        renderChecked(shadowCullingOptions(RenderMode::Decoupled, ShadowCulling::WholeScene));
    EXPECT_LT(drawn(perView, "spot_shadow_0") * 4, drawn(wholeScene, "spot_shadow_0"));
    double p = psnr(perView.frames[0].rgba, wholeScene.frames[0].rgba);
    std::printf("[ figures ] decoupled per-view vs whole-scene %.2f dB\n", p);
    EXPECT_GE(p, 60.0);
    EXPECT_EQ(cullingDispatches(perView), 1u);
}

TEST(ShadowCulling, BadModeIsAnInputError) {
    std::string err = tempPath("shadow-culling-err.txt");
    std::string cmd =
        std::string("timeout 120 ") + SHADEL_BINARY +
        " render --scene builtin:lights --size 32x32 --shadow-culling some >/dev/null "
        "2>" +
        err;
    int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 2);
    std::ifstream in(err);
    std::stringstream text;
    text << in.rdbuf();
    std::string message = text.str();
    EXPECT_NE(message.find("--shadow-culling"), std::string::npos) << message;
    EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
}
