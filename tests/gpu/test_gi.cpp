// Light propagation volume GI (render/gi): colour bleeding on builtin:cornell, stable
// cascades under camera motion, stats and bad input.
#include "gpu_test_env.h"

#include "gi/gi_types.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>

using namespace shadel;
using namespace shadel::test;

namespace {

constexpr uint32_t kW = 160, kH = 90;
// Floor only, along the red wall, in the main camera's 160x90 view (outside the spot's cone).
constexpr int kFloorX0 = 34, kFloorY0 = 62, kFloorX1 = 56, kFloorY1 = 88;

RenderOptions cornell(GiMode gi) {
    RenderOptions o = renderOptions("builtin:cornell", RenderMode::Forward, kW, kH);
    o.gi = gi;
    return o;
}

// Mean red, green over a pixel rectangle of an RGBA8 image.
std::pair<double, double> meanRedGreen(const std::vector<uint8_t>& rgba, int x0, int y0, int x1,
                                       int y1) {
    double r = 0, g = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            size_t i = (size_t(y) * kW + size_t(x)) * 4;
            r += rgba[i];
            g += rgba[i + 1];
        }
    double n = double(x1 - x0) * double(y1 - y0);
    return {r / n, g / n};
}

double floorRedOverGreen(const RenderRun& run) {
    auto [r, g] = meanRedGreen(run.frames[0].rgba, kFloorX0, kFloorY0, kFloorX1, kFloorY1);
    return r / std::max(g, 1.0);
}

// GI-only red light (red above green) over columns [x0, x1) of the first frame.
double redLight(const RenderRun& run, uint32_t x0, uint32_t x1) {
    double sum = 0;
    for (uint32_t y = 0; y < kH; ++y)
        for (uint32_t x = x0; x < x1; ++x) {
            const uint8_t* p = &run.frames[0].rgba[(y * kW + x) * 4];
            sum += std::max(0, int(p[0]) - int(p[1]));
        }
    return sum;
}

// The blocker of BlockerStopsPropagationIntoTheRoomBeyondIt: across the room and far beyond,
// 0.7 m in front of the red wall.
GiBlocker wallAcrossTheRoom() {
    GiBlocker wall;
    wall.center = glm::vec3(-1.3f, 1.6f, 0.0f);
    wall.axisU = glm::vec3(0, 0, 1);
    wall.axisV = glm::vec3(0, 1, 0);
    wall.halfSize = glm::vec2(20.0f, 20.0f);
    return wall;
}

} // namespace

// The floor by the front half of the red wall gets no direct light (the spot lights the wall's
// back half), so with GI off it is the white floor under grey ambient: red/green about 1. The
// LPV carries the light the red wall reflects onto it.
TEST(Gi, CornellFloorByTheRedWallBleedsRed) {
    RenderRun off = renderChecked(cornell(GiMode::Off));
    RenderRun on = renderChecked(cornell(GiMode::Lpv));
    // Measured 1.00 off, 1.38 on (the room's local volume, 32 propagation steps; the cascades
    // alone, 8 steps: 1.27); the margin asked is 1.15x.
    double ratioOff = floorRedOverGreen(off), ratioOn = floorRedOverGreen(on);
    std::printf("floor by the red wall, red/green: GI off %.3f, on %.3f\n", ratioOff, ratioOn);
    EXPECT_GT(ratioOn, ratioOff * 1.15) << "off " << ratioOff << ", on " << ratioOn;
    // What GI adds there is red light: not a brightening that happens to raise the ratio.
    auto [rOff, gOff] = meanRedGreen(off.frames[0].rgba, kFloorX0, kFloorY0, kFloorX1, kFloorY1);
    auto [rOn, gOn] = meanRedGreen(on.frames[0].rgba, kFloorX0, kFloorY0, kFloorX1, kFloorY1);
    EXPECT_GT(rOn - rOff, 4.0 * std::max(gOn - gOff, 0.25)) << rOn << " " << gOn;

    const auto& s = on.stats;
    ASSERT_TRUE(s.contains("gi"));
    EXPECT_EQ(s["gi"]["cascades"].size(), 3u);
    EXPECT_EQ(s["gi"]["iterations"].get<uint32_t>(), 8u);
    EXPECT_EQ(s["gi"]["reflective_shadow_maps"].get<uint32_t>(), 1u) << "the cornell spot";
    double c0 = s["gi"]["cascades"][0]["cell_size"].get<double>();
    EXPECT_DOUBLE_EQ(s["gi"]["cascades"][1]["cell_size"].get<double>(), 2 * c0);
    std::vector<std::string> passes;
    for (auto& p : s["passes"]) passes.push_back(p["name"]);
    for (const char* name : {"giReflectiveShadowMaps", "giInject", "giPropagate"})
        EXPECT_NE(std::find(passes.begin(), passes.end(), name), passes.end()) << name;
    EXPECT_FALSE(off.stats.contains("gi"));
}

// The decoupled path shades with the same lighting code, so it bleeds too.
TEST(Gi, DecoupledShadelsGetTheIndirectLight) {
    RenderOptions o = cornell(GiMode::Off);
    o.mode = RenderMode::Decoupled;
    RenderRun off = renderChecked(o);
    o.gi = GiMode::Lpv;
    RenderRun on = renderChecked(o);
    EXPECT_GT(floorRedOverGreen(on), floorRedOverGreen(off) * 1.15);
}

// Cascades snapped to their cell size keep every surface in its cells while the camera moves;
// sliding cascades re-sample the light each frame (swimming). Measured on the GI-only image.
TEST(Gi, SnappedCascadesSwimAtMostHalfAsMuchUnderOrbit) {
    RenderOptions o = cornell(GiMode::Lpv);
    o.giLocalVolumes = false; // the room's fixed volume would hold every point of the view
    o.visualize = Visualize::Gi;
    o.cameraPath = CameraPath::Orbit;
    // 12 frames over the 40-degree orbit: steps of about a cell of cascade 0. Measured: mean
    // frame delta 0.80 snapped, 2.34 sliding (0.34x).
    o.width = 128;
    o.height = 72;
    o.frames = 12;
    RenderRun snapped = renderChecked(o);
    o.giSnap = false;
    RenderRun sliding = renderChecked(o);
    double dSnapped = meanFrameDelta(snapped), dSliding = meanFrameDelta(sliding);
    std::printf("GI-only mean frame delta: snapped %.3f, sliding %.3f\n", dSnapped, dSliding);
    EXPECT_GT(dSliding, 0.0);
    EXPECT_LE(dSnapped, 0.5 * dSliding) << "snapped " << dSnapped << ", sliding " << dSliding;
}

TEST(Gi, BadFlagsAreOneLineAndExitCode2) {
    std::string err = tempPath("gi_stderr.txt");
    for (const std::string args :
         {"render --size 16x16 --gi radiosity", "render --size 16x16 --gi-snap maybe",
          "render --size 16x16 --scene builtin:cornell --gi lpv --gi-iterations 65",
          "render --size 16x16 --scene builtin:cornell --visualize gi",
          "render --size 16x16 --scene builtin:cornell --gi lpv --gi-local-volumes some"}) {
        std::string cmd =
            std::string("timeout 120 ") + SHADEL_BINARY + " " + args + " >/dev/null 2>" + err;
        int status = std::system(cmd.c_str());
        EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 2) << args;
        std::ifstream in(err);
        std::stringstream ss;
        ss << in.rdbuf();
        std::string text = ss.str();
        EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << args << ": " << text;
        EXPECT_NE(text.find("--gi"), std::string::npos) << args << ": " << text;
        EXPECT_NE(text.find("shadel: "), std::string::npos) << args;
    }
}

// The lights' views are fixed, so the RSMs are drawn once and a cascade is updated only when it
// moves: a static camera updates each cascade once and keeps the same image. A moving spot
// (--animate-lights) needs its RSM and every cascade again each frame.
TEST(Gi, StaticCameraReusesTheVolumesAndMovingSpotsRedrawThem) {
    RenderOptions o = cornell(GiMode::Lpv);
    o.width = 64;
    o.height = 36;
    o.frames = 3;
    RenderRun still = renderChecked(o);
    EXPECT_EQ(still.stats["gi"]["rsm_renders"].get<uint64_t>(), 1u);
    EXPECT_EQ(still.stats["gi"]["cascade_updates"].get<uint64_t>(), 3u);
    EXPECT_EQ(still.stats["gi"]["local_volume_updates"].get<uint64_t>(), 1u);
    EXPECT_EQ(still.frames[0].rgba, still.frames[2].rgba);
    o.animateLights = true;
    RenderRun moving = renderChecked(o);
    EXPECT_EQ(moving.stats["gi"]["rsm_renders"].get<uint64_t>(), 3u);
    EXPECT_EQ(moving.stats["gi"]["cascade_updates"].get<uint64_t>(), 9u);
    EXPECT_EQ(moving.stats["gi"]["local_volume_updates"].get<uint64_t>(), 3u);
}

// builtin:cornell places a local volume over its room (artist-placed volumes): a
// fixed grid of cells half as wide as cascade 0's, propagated GI_GRID steps once. The camera
// orbits, the cascades follow it, the room's volume stays computed; inside the room the apply
// reads it before the cascades, so the indirect light differs from the cascades' alone.
TEST(Gi, TheRoomsLocalVolumeIsComputedOnceAndReadBeforeTheCascades) {
    RenderOptions o = cornell(GiMode::Lpv);
    o.visualize = Visualize::Gi;
    o.cameraPath = CameraPath::Orbit;
    o.frames = 4;
    RenderRun local = renderChecked(o);
    const nlohmann::json& gi = local.stats["gi"];
    ASSERT_EQ(gi["local_volumes"].size(), 1u);
    EXPECT_EQ(gi["local_volumes"][0]["name"], "room");
    EXPECT_EQ(gi["local_volumes"][0]["propagation_steps"].get<uint32_t>(), GI_GRID);
    EXPECT_LT(gi["local_volumes"][0]["cell_size"].get<double>(),
              gi["cascades"][0]["cell_size"].get<double>());
    EXPECT_EQ(gi["local_volume_updates"].get<uint64_t>(), 1u) << "fixed: computed once";
    EXPECT_GT(gi["cascade_updates"].get<uint64_t>(), 3u) << "the cascades follow the camera";
    EXPECT_EQ(gi["cells"].get<uint64_t>(), 4u * GI_GRID * GI_GRID * GI_GRID);

    o.giLocalVolumes = false;
    RenderRun cascades = renderChecked(o);
    EXPECT_TRUE(cascades.stats["gi"]["local_volumes"].empty());
    EXPECT_EQ(cascades.stats["gi"]["local_volume_updates"].get<uint64_t>(), 0u);
    // The GI-only image is dark (indirect light only): compare the change to the light itself.
    double light = 0.0, change = 0.0;
    for (size_t i = 0; i < local.frames[0].rgba.size(); ++i) {
        if (i % 4 == 3) continue;
        light += local.frames[0].rgba[i];
        change += std::abs(int(local.frames[0].rgba[i]) - int(cascades.frames[0].rgba[i]));
    }
    std::printf("GI only, room volume vs cascades only: %.2f dB, change %.3f of the light\n",
                psnr(local.frames[0].rgba, cascades.frames[0].rgba), change / light);
    // Measured: 0.123 of the light (38.0 dB; the image is mostly dark); half of that is asked.
    EXPECT_GT(change, 0.06 * light) << "the room's volume is what the apply reads in the room";
}

// A blocker (a rectangle light does not propagate through) across the room and beyond, 0.7 m in
// front of the red wall, the only lit surface: the room beyond it gets at most 10% of the
// indirect light it gets without the blocker, while the red wall's side keeps its light.
TEST(Gi, BlockerStopsPropagationIntoTheRoomBeyondIt) {
    RenderOptions o = cornell(GiMode::Lpv);
    o.visualize = Visualize::Gi;
    o.exposure = 16.0f; // the light beyond is dim: lift it well above 8-bit quantisation
    RenderRun open = renderChecked(o);
    // Larger than the room: light must not go round it either (through cells outside the
    // room, whose walls the spot's RSM does not see, so they do not occlude).
    GiBlocker wall = wallAcrossTheRoom();
    o.giBlockers = {wall};
    RenderRun blocked = renderChecked(o);
    EXPECT_EQ(blocked.stats["gi"]["blockers"].get<uint32_t>(), 1u);
    // Columns from 64 on see the room at x > -1.0 (back wall, floor, block, green wall). The red
    // wall's light is counted as red above green: the spot also grazes the white top of the
    // ceiling by the opening, on the room's side of the blocker, and that light may enter.
    double beyondOpen = redLight(open, 64, kW), beyondBlocked = redLight(blocked, 64, kW);
    std::printf("GI-only red light beyond the blocker: %.0f without, %.0f with (%.1f%%)\n",
                beyondOpen, beyondBlocked, 100.0 * beyondBlocked / beyondOpen);
    EXPECT_GT(beyondOpen, 0.0);
    EXPECT_LE(beyondBlocked, 0.1 * beyondOpen);
    EXPECT_GE(redLight(blocked, 0, 24), 0.5 * redLight(open, 0, 24)) << "the red wall's side";
}

// Portals are holes in blockers, in GI as in direct light: the wall across the room
// with a portal as large as the room's cross-section lets the red wall's light into the room
// again (the part of the wall outside the room still blocks).
TEST(Gi, PortalInABlockerLetsTheLightThrough) {
    RenderOptions o = cornell(GiMode::Lpv);
    o.visualize = Visualize::Gi;
    o.exposure = 16.0f;
    RenderRun open = renderChecked(o);
    GiBlocker wall = wallAcrossTheRoom();
    o.giBlockers = {wall};
    RenderRun blocked = renderChecked(o);
    // The room's interior: z in [-2, 2], y in [0.1, 3.1] (u along z, v along y from y = 1.6).
    wall.portals = {glm::vec4(-2.0f, -1.5f, 2.0f, 1.5f)};
    o.giBlockers = {wall};
    RenderRun portal = renderChecked(o);
    EXPECT_EQ(portal.stats["gi"]["portals"].get<uint32_t>(), 1u);
    double beyondOpen = redLight(open, 64, kW), beyondBlocked = redLight(blocked, 64, kW),
           beyondPortal = redLight(portal, 64, kW);
    std::printf("[ figures ] GI-only red light beyond the wall: open %.0f, blocked %.0f, with a "
                "room-sized portal %.0f (%.1f%% of open)\n",
                beyondOpen, beyondBlocked, beyondPortal, 100.0 * beyondPortal / beyondOpen);
    EXPECT_GE(beyondPortal, 0.7 * beyondOpen);
    EXPECT_GE(beyondPortal, 3.0 * beyondBlocked);
}

// Macro-cell culling (blockers culled against 4x4x4 macro-cells) only skips blockers
// that cannot cut a tap: the image is the one of testing every blocker, while a macro-cell
// tests a fraction of them.
TEST(Gi, MacroCellBlockerCullingChangesNothing) {
    RenderOptions o = cornell(GiMode::Lpv);
    o.visualize = Visualize::Gi;
    o.exposure = 16.0f;
    GiBlocker wall = wallAcrossTheRoom();
    wall.halfSize = glm::vec2(1.8f, 1.4f); // inside the room: light goes round it
    wall.portals = {glm::vec4(-0.5f, -1.4f, 0.5f, 0.6f)};
    o.giBlockers = {wall};
    // Small blockers elsewhere in the volumes (outside the room), which most cells skip.
    for (int i = 0; i < 12; ++i) {
        GiBlocker b;
        b.center = glm::vec3(-10.0f + 2.0f * float(i), 1.0f, 8.0f + float(i % 3));
        b.axisU = glm::vec3(1, 0, 0);
        b.axisV = glm::vec3(0, 1, 0);
        b.halfSize = glm::vec2(0.5f, 0.5f);
        o.giBlockers.push_back(b);
    }
    RenderRun culled = renderChecked(o);
    o.giBlockerCells = false;
    RenderRun all = renderChecked(o);
    double perCell = culled.stats["gi"]["blockers_per_macro_cell"].get<double>();
    double p = psnr(culled.frames[0].rgba, all.frames[0].rgba);
    std::printf("[ figures ] cornell GI, 13 blockers: %.3f tested per macro-cell; culled vs all "
                "%.2f dB\n",
                perCell, p);
    EXPECT_GE(p, 60.0);
    EXPECT_LT(perCell, 1.0);
    EXPECT_GT(perCell, 0.0);
}
