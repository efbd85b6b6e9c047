// Lighting: tiled light culling changes nothing in the image, in both
// paths, on a night street of >= 2000 lights of every kind; light blockers keep a room's light
// inside its walls, and their portals let it out through the doorway.
#include "gpu_test_env.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>

#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"
#include "render/camera.h"
#include "scene/builtin_scenes.h"

using namespace shadel;
using namespace shadel::test;

namespace {

RenderOptions lightsOptions(RenderMode mode, LightCulling culling) {
    RenderOptions o = renderOptions("builtin:lights", mode, 192, 108);
    o.lightCulling = culling;
    return o;
}

void expectCullingChangesNothing(RenderMode mode) {
    RenderRun none = renderChecked(lightsOptions(mode, LightCulling::None));
    RenderRun tiled = renderChecked(lightsOptions(mode, LightCulling::Tiled));
    const auto& s = tiled.stats;
    EXPECT_GE(s["lights"].get<uint64_t>(), 2000u);
    EXPECT_EQ(s["light_tiles_overflowed"].get<uint64_t>(), 0u) << "a tile's list was cut short";
    EXPECT_EQ(s["light_chunks_overflowed"].get<uint64_t>(), 0u) << "a chunk's list was cut short";
    uint64_t visible = s["lights_visible"].get<uint64_t>();
    EXPECT_GT(visible, 50u) << "the night street should see many lights";
    EXPECT_LT(visible, s["lights"].get<uint64_t>()) << "lights far behind the camera are culled";
    EXPECT_EQ(none.stats["lights_visible"].get<uint64_t>() + 1,
              none.stats["lights"].get<uint64_t>())
        << "without culling every light but the moon is considered everywhere";
    if (mode == RenderMode::Decoupled) {
        EXPECT_EQ(s["light_chunk_unit"], "chunk") << "thousands of lights: whole chunks cull";
    }
    double p = psnr(none.frames[0].rgba, tiled.frames[0].rgba);
    EXPECT_GE(p, 45.0) << "culling must not change the image";
    // Not a trivially equal pair: the scene is lit by the culled lights (not black, not flat).
    double sum = 0;
    for (size_t i = 0; i < tiled.frames[0].rgba.size(); i += 4) sum += tiled.frames[0].rgba[i + 1];
    EXPECT_GT(sum / (192.0 * 108.0), 8.0);
}

// Ground-plane position (x, z) seen through pixel (px, py) of the blockers scene's top camera.
glm::vec2 groundAt(const CameraView& v, uint32_t w, uint32_t h, uint32_t px, uint32_t py) {
    glm::mat4 inv = glm::inverse(v.proj * v.view);
    glm::vec2 ndc((float(px) + 0.5f) / float(w) * 2.0f - 1.0f,
                  (float(py) + 0.5f) / float(h) * 2.0f - 1.0f);
    glm::vec4 a = inv * glm::vec4(ndc, 1.0f, 1.0f), b = inv * glm::vec4(ndc, 0.5f, 1.0f);
    glm::vec3 p0 = glm::vec3(a) / a.w, p1 = glm::vec3(b) / b.w;
    float t = p0.y / (p0.y - p1.y);
    glm::vec3 g = p0 + (p1 - p0) * t;
    return {g.x, g.z};
}

double luminance(const std::vector<uint8_t>& px, size_t i) {
    return 0.2126 * px[i] + 0.7152 * px[i + 1] + 0.0722 * px[i + 2];
}

} // namespace

TEST(Lighting, TiledCullingChangesNothingForward) {
    expectCullingChangesNothing(RenderMode::Forward);
}

TEST(Lighting, ChunkCullingChangesNothingDecoupled) {
    expectCullingChangesNothing(RenderMode::Decoupled);
}

// With few lights every subgroup culls them for its own pixels or shadels (no tile pass, no
// chunk culling: light_cull.glsl useSubgroupLightList); the sum is the one over every light.
void expectSubgroupCullingChangesNothing(RenderMode mode) {
    RenderOptions o = renderOptions("builtin:default", mode, 320, 180);
    o.lightCulling = LightCulling::None;
    RenderRun none = renderChecked(o);
    o.lightCulling = LightCulling::Tiled;
    RenderRun culled = renderChecked(o);
    const auto& s = culled.stats;
    ASSERT_LT(s["lights"].get<uint64_t>(), 16u) << "below the screen tiles' threshold";
    EXPECT_EQ(s["light_culling"], "subgroups (few lights)");
    EXPECT_EQ(none.stats["light_culling"], "none");
    EXPECT_FALSE(s["light_screen_tiles"].get<bool>()) << "no tile pass";
    EXPECT_FALSE(s["light_tile_split"].get<bool>()) << "no second light loop without tile lists";
    uint64_t visible = s["lights_visible"].get<uint64_t>();
    EXPECT_GT(visible, 0u) << "the street lamps light some pixels";
    EXPECT_LT(visible, s["lights"].get<uint64_t>()) << "some lamps reach no shaded subgroup";
    if (mode == RenderMode::Decoupled) {
        EXPECT_EQ(s["light_chunk_unit"], "subgroup");
        uint64_t pairs = s["light_chunk_pairs"].get<uint64_t>();
        uint64_t tested = s["light_chunk_candidates"].get<uint64_t>();
        EXPECT_GT(s["light_subgroup_lists"].get<uint64_t>(), s["chunks_shaded"].get<uint64_t>())
            << "several subgroups per chunk";
        EXPECT_GT(pairs, 0u);
        EXPECT_LT(pairs * 2, tested) << "most (light, subgroup) pairs are culled";
    }
    EXPECT_GE(psnr(none.frames[0].rgba, culled.frames[0].rgba), 60.0)
        << "the same sum: culled lights add nothing";
    if (mode == RenderMode::Decoupled) {
        // The counts are the last frame's, not a sum over frames: three frames of a still
        // camera, every chunk shaded again, count what one frame counts.
        o.reuse = false;
        RenderRun one = renderChecked(o);
        o.frames = 3;
        RenderRun three = renderChecked(o);
        for (const char* key : {"light_subgroup_lists", "light_chunk_pairs", "lights_visible"})
            EXPECT_EQ(three.stats[key], one.stats[key]) << key;
    }
}

TEST(Lighting, FewLightsAreCulledPerSubgroupForward) {
    expectSubgroupCullingChangesNothing(RenderMode::Forward);
}

TEST(Lighting, FewLightsAreCulledPerSubgroupInTheShadelPath) {
    expectSubgroupCullingChangesNothing(RenderMode::Decoupled);
}

TEST(Lighting, TiledCullingCountsPairsAndCullsMostOfThem) {
    RenderRun run = renderChecked(lightsOptions(RenderMode::Forward, LightCulling::Tiled));
    const auto& s = run.stats;
    uint64_t pairs = s["light_tile_pairs"].get<uint64_t>();
    uint64_t tiles = s["light_tiles"].get<uint64_t>();
    EXPECT_GT(pairs, tiles) << "most covered tiles see more than one light";
    EXPECT_LT(pairs, tiles * s["lights"].get<uint64_t>() / 10) << "culling keeps < 10% of pairs";
    EXPECT_GT(s["per_pixel_blocker_tiles"].get<uint64_t>(), 0u)
        << "the rooms' doorways and wall edges straddle blocker frusta";
    EXPECT_LT(s["per_pixel_blocker_tiles"].get<uint64_t>(), tiles * 3 / 4)
        << "tiles away from the rooms need no per-pixel blocker test";
    EXPECT_GT(s["lights_culled_by_blockers"].get<uint64_t>(), 0u)
        << "tiles wholly behind a wall drop its lamps";
    // Spectra per light: the street's shadowed spots, gobos and area lights read textures, most
    // of its lamps do not; the forward pass shades those first without the texture code.
    EXPECT_TRUE(s["light_tile_split"].get<bool>());
    EXPECT_GT(s["light_tile_plain_pairs"].get<uint64_t>(), pairs / 2);
    EXPECT_LT(s["light_tile_plain_pairs"].get<uint64_t>(), pairs);
}

// builtin:blockers: a roofless room with a lamp; seen from straight above, pixels map to the
// ground. Outside the walls (except in front of the doorway) the lamp's light is leakage.
TEST(Lighting, BlockersKeepTheRoomLightInsideAndPortalsLetItOut) {
    const uint32_t w = 192, h = 108;
    RenderOptions o = renderOptions("builtin:blockers", RenderMode::Forward, w, h);
    o.lightBlockers = false;
    RenderRun off = renderChecked(o);
    o.lightBlockers = true;
    RenderRun on = renderChecked(o);
    o.lightCulling = LightCulling::None; // per-pixel blocker tests everywhere
    RenderRun onNone = renderChecked(o);
    EXPECT_GT(on.stats["per_pixel_blocker_tiles"].get<uint64_t>(), 0u);
    EXPECT_GT(on.stats["lights_culled_by_blockers"].get<uint64_t>(), 0u)
        << "tiles wholly in a wall's shadow drop the lamp";

    Scene scene = makeBuiltinScene("blockers");
    CameraView view = makeCameraView(findCamera(scene, ""), w, h);
    // Room interior |x|, |z| < 2; walls to 2.2; doorway |x| < 0.5 in the +z wall.
    double outsideOn = 0, outsideOff = 0, doorOn = 0, doorOff = 0;
    std::vector<uint8_t> insideOn, insideOff;
    size_t outsidePixels = 0, doorPixels = 0;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            glm::vec2 g = groundAt(view, w, h, x, y);
            size_t i = (size_t(y) * w + x) * 4;
            float m = std::max(std::abs(g.x), std::abs(g.y));
            if (m < 1.6f) { // inside, away from the walls' tops
                for (int c = 0; c < 4; ++c) {
                    insideOn.push_back(on.frames[0].rgba[i + c]);
                    insideOff.push_back(off.frames[0].rgba[i + c]);
                }
            } else if (m > 3.0f && g.y < 1.5f) { // outside, not where the doorway shines
                outsideOn += luminance(on.frames[0].rgba, i);
                outsideOff += luminance(off.frames[0].rgba, i);
                outsidePixels++;
            } else if (g.y > 3.0f && g.y < 4.5f && std::abs(g.x) < 0.4f) { // before the door
                doorOn += luminance(on.frames[0].rgba, i);
                doorOff += luminance(off.frames[0].rgba, i);
                doorPixels++;
            }
        }
    ASSERT_GT(outsidePixels, 1000u);
    ASSERT_GT(doorPixels, 4u);
    ASSERT_GT(insideOn.size(), 400u);
    EXPECT_GT(outsideOff / double(outsidePixels), 5.0) << "without blockers the lamp leaks out";
    EXPECT_LE(outsideOn, 0.05 * outsideOff) << "blockers must stop the leak";
    EXPECT_GE(psnr(insideOn, insideOff), 45.0) << "inside, blockers change nothing";
    EXPECT_GE(doorOn, 0.9 * doorOff) << "the doorway is a portal: light goes out through it";
    EXPECT_GE(psnr(on.frames[0].rgba, onNone.frames[0].rgba), 45.0)
        << "tile culling against blocker frusta gives the per-pixel result";
}

TEST(Lighting, BlockersAlsoStopLightInTheShadelPath) {
    const uint32_t w = 192, h = 108;
    RenderOptions o = renderOptions("builtin:blockers", RenderMode::Decoupled, w, h);
    o.lightBlockers = false;
    RenderRun off = renderChecked(o);
    o.lightBlockers = true;
    RenderRun on = renderChecked(o);
    Scene scene = makeBuiltinScene("blockers");
    CameraView view = makeCameraView(findCamera(scene, ""), w, h);
    double outsideOn = 0, outsideOff = 0;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            glm::vec2 g = groundAt(view, w, h, x, y);
            if (std::max(std::abs(g.x), std::abs(g.y)) > 3.0f && g.y < 1.5f) {
                outsideOn += luminance(on.frames[0].rgba, (size_t(y) * w + x) * 4);
                outsideOff += luminance(off.frames[0].rgba, (size_t(y) * w + x) * 4);
            }
        }
    EXPECT_GT(outsideOff, 0.0);
    EXPECT_LE(outsideOn, 0.05 * outsideOff);
    EXPECT_GT(on.stats["per_pixel_blocker_chunks"].get<uint64_t>(), 0u);
}

TEST(Lighting, VisualizeLightCountShowsMoreLightsWhereTheyCluster) {
    RenderOptions o = lightsOptions(RenderMode::Forward, LightCulling::Tiled);
    o.visualize = Visualize::LightCount;
    RenderRun run = renderChecked(o);
    const auto& px = run.frames[0].rgba;
    int distinct = 0;
    std::vector<bool> seen(1 << 12, false);
    for (size_t i = 0; i < px.size(); i += 4) {
        int key = (px[i] >> 4) << 8 | (px[i + 1] >> 4) << 4 | (px[i + 2] >> 4);
        if (!seen[size_t(key)]) seen[size_t(key)] = true, distinct++;
    }
    EXPECT_GT(distinct, 8) << "a heat map of light counts, not a flat image";
}

TEST(Lighting, BadLightingFlagsAreOneLineErrors) {
    EXPECT_THROW(parseLightCulling("clustered"), InputError);
    EXPECT_THROW(parseOnOff("--blockers", "yes"), InputError);
    try {
        parseLightCulling("clustered");
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--light-culling clustered"), std::string::npos);
    }
    EXPECT_EQ(parseVisualize("light-count"), Visualize::LightCount);
    EXPECT_EQ(parseVisualize("blockers"), Visualize::Blockers);
    std::string err = tempPath("lighting_err.txt");
    std::string cmd =
        std::string("timeout 120 ") + SHADEL_BINARY +
        " render --scene builtin:blockers --size 32x32 --blockers maybe >/dev/null 2>" + err;
    int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 2);
    std::ifstream in(err);
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_NE(text.str().find("--blockers maybe"), std::string::npos) << text.str();
}

// With two-phase occlusion culling the depth buffer is complete only after the second phase;
// the tile pass takes its depth bounds after it (before, every tile the second phase filled
// was culled as sky and lost its lights: 8.5 dB).
TEST(Lighting, TilesCullAgainstTheDepthOcclusionCullingCompletes) {
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        RenderOptions o = lightsOptions(mode, LightCulling::Tiled);
        RenderRun off = renderChecked(o);
        o.occlusion = true;
        RenderRun on = renderChecked(o);
        EXPECT_GE(psnr(on.frames[0].rgba, off.frames[0].rgba), 50.0)
            << (mode == RenderMode::Forward ? "forward" : "decoupled");
    }
}
