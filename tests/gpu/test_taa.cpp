// Temporal anti-aliasing (--aa taa, render/taa), judged against 8x8 supersampled renders of
// the same cameras: closer to them than the aliased frames on an orbit, steady on a still
// camera where jittered aliased frames flicker, and no trail behind a moving object.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "gpu_test_env.h"
#include "scene_files.h"

namespace shadel::test {
namespace {

constexpr uint32_t kW = 320, kH = 180;

// Mean PSNR of frames [from, end) of `run` against the same frames of `reference`.
double meanPsnr(const RenderRun& run, const RenderRun& reference, size_t from) {
    double sum = 0.0;
    for (size_t i = from; i < run.frames.size(); ++i)
        sum += psnr(run.frames[i].rgba, reference.frames[i].rgba);
    return sum / double(run.frames.size() - from);
}

// Mean absolute difference (8-bit levels, RGB) between consecutive frames from `from` on.
double frameDelta(const RenderRun& run, size_t from) {
    double sum = 0.0;
    size_t n = 0;
    for (size_t f = std::max<size_t>(from, 1); f < run.frames.size(); ++f) {
        const std::vector<uint8_t>& a = run.frames[f - 1].rgba;
        const std::vector<uint8_t>& b = run.frames[f].rgba;
        for (size_t i = 0; i < a.size(); i += 4)
            for (int c = 0; c < 3; ++c, ++n) sum += std::abs(double(a[i + c]) - double(b[i + c]));
    }
    return sum / double(std::max<size_t>(n, 1));
}

RenderOptions orbitOptions(RenderMode mode, uint32_t frames) {
    RenderOptions o = renderOptions("builtin:default", mode, kW, kH);
    o.progress = false;
    o.frames = frames;
    o.cameraPath = CameraPath::Orbit;
    return o;
}

// TAA frames of an orbit are closer to the supersampled frames than the aliased ones, in both
// paths (the reference is forward 8x8 SSAA for both). Frames after the first 4 (warm-up).
void expectOrbitCloserToSsaa(RenderMode mode, double floorGainDb) {
    const uint32_t frames = 12;
    RenderOptions reference = orbitOptions(RenderMode::Forward, frames);
    reference.ssaa = 8;
    RenderRun ssaa = renderChecked(reference);
    RenderOptions none = orbitOptions(mode, frames);
    none.aa = AntiAliasing::None;
    RenderOptions taa = orbitOptions(mode, frames);
    taa.aa = AntiAliasing::Taa;
    RenderRun noneRun = renderChecked(none), taaRun = renderChecked(taa);
    double psnrNone = meanPsnr(noneRun, ssaa, 4), psnrTaa = meanPsnr(taaRun, ssaa, 4);
    std::printf("%s orbit: no AA %.2f dB, TAA %.2f dB\n", modeName(mode), psnrNone, psnrTaa);
    EXPECT_GE(psnrTaa, psnrNone + floorGainDb)
        << modeName(mode) << ": TAA " << psnrTaa << " dB, no AA " << psnrNone << " dB";
    EXPECT_TRUE(taaRun.stats["taa"]["enabled"].get<bool>());
    bool resolved = false;
    for (const auto& p : taaRun.stats["passes"]) resolved |= p["name"] == "taaResolve";
    EXPECT_TRUE(resolved) << "no taaResolve pass in the stats";
}

// A dark wall (8 x 4 m at z = 0) and a white, glowing 1 m cube 1 m in front of it that an
// animation slides from x = -3 to x = 3 over 2 s. Written as FILE.gltf + FILE.bin.
std::string writeMovingCubeScene(const std::string& name) {
    nlohmann::json dark = {{"pbrMetallicRoughness",
                            {{"baseColorFactor", {0.03, 0.03, 0.03, 1.0}},
                             {"metallicFactor", 0.0},
                             {"roughnessFactor", 0.9}}}};
    nlohmann::json white = {{"pbrMetallicRoughness",
                             {{"baseColorFactor", {1.0, 1.0, 1.0, 1.0}},
                              {"metallicFactor", 0.0},
                              {"roughnessFactor", 0.9}}},
                            {"emissiveFactor", {1.0, 1.0, 1.0}}};
    SlidingCubeScene scene{{glm::vec3(-4.0f, -0.5f, 0.0f), glm::vec3(4.0f, -0.5f, 0.0f),
                            glm::vec3(-4.0f, 3.5f, 0.0f), glm::vec3(4.0f, 3.5f, 0.0f)},
                           glm::vec3(0.0f, 0.0f, 1.0f),
                           {0, 1, 2, 2, 1, 3},
                           glm::vec3(-3.0f, 1.5f, 1.0f),
                           glm::vec3(3.0f, 1.5f, 1.0f),
                           "wall",
                           "cube",
                           dark,
                           white};
    return writeSlidingCubeScene(name, scene);
}

// Per pixel of an RGBA8 image: its brightest channel.
std::vector<uint8_t> brightest(const std::vector<uint8_t>& rgba) {
    std::vector<uint8_t> out(rgba.size() / 4);
    for (size_t i = 0; i < out.size(); ++i)
        out[i] = std::max({rgba[i * 4], rgba[i * 4 + 1], rgba[i * 4 + 2]});
    return out;
}

// The trail: over the pixels the reference shows as wall in frame `f` (at least 2 pixels from
// the cube) but as cube in one of the 3 frames before, the largest amount (8-bit levels of the
// brightest channel) by which `run` is brighter than the reference. `pixels`: how many.
int worstTrail(const RenderRun& run, const RenderRun& reference, size_t f, size_t& pixels) {
    const int cube = 128; // the glowing cube is white, the wall near black
    std::vector<uint8_t> now = brightest(reference.frames[f].rgba);
    std::vector<uint8_t> shown = brightest(run.frames[f].rgba);
    std::vector<std::vector<uint8_t>> earlier;
    for (size_t back = 1; back <= 3 && back <= f; ++back)
        earlier.push_back(brightest(reference.frames[f - back].rgba));
    int worst = 0;
    pixels = 0;
    for (int y = 0; y < int(kH); ++y) {
        for (int x = 0; x < int(kW); ++x) {
            bool nearCube = false;
            for (int dy = -2; dy <= 2; ++dy)
                for (int dx = -2; dx <= 2; ++dx) {
                    int qx = std::clamp(x + dx, 0, int(kW) - 1);
                    int qy = std::clamp(y + dy, 0, int(kH) - 1);
                    nearCube |= now[size_t(qy) * kW + size_t(qx)] >= cube;
                }
            bool before = false;
            for (const std::vector<uint8_t>& e : earlier)
                before |= e[size_t(y) * kW + size_t(x)] >= cube;
            if (nearCube || !before) continue;
            size_t i = size_t(y) * kW + size_t(x);
            ++pixels;
            worst = std::max(worst, int(shown[i]) - int(now[i]));
        }
    }
    return worst;
}

} // namespace

// Forward: the aliased frames' textures and edges shimmer (measured 22.4 dB no AA, 28.6 dB
// TAA).
TEST(Taa, OrbitForwardIsCloserToSupersamplingThanNoAa) {
    expectOrbitCloserToSsaa(RenderMode::Forward, 5.0);
}

// Decoupled: shading is prefiltered in shadel space, only geometric edges alias (32.9 dB no
// AA); on this fast orbit (3.3 degrees a frame) the resampled history's softness costs more
// than the edges gain (measured 32.2 dB, -0.8 dB). The floor keeps it from getting worse; a
// still gains (docs/taa.md: +2.2 dB).
TEST(Taa, OrbitDecoupledStaysNearSupersamplingUnderMotion) {
    expectOrbitCloserToSsaa(RenderMode::Decoupled, -2.2);
}

// Still camera, jitter on: aliased frames change with every sub-pixel offset (edges step by a
// pixel), TAA's converge. Differences between consecutive frames after 8 warm-up frames
// (measured: forward 8.57 -> 0.58 levels, decoupled 2.70 -> 0.20).
TEST(Taa, StillCameraDoesNotFlickerUnderJitter) {
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        RenderOptions none = renderOptions("builtin:default", mode, kW, kH);
        none.progress = false;
        none.frames = 16;
        none.jitter = true;
        none.aa = AntiAliasing::None;
        RenderOptions taa = none;
        taa.aa = AntiAliasing::Taa;
        double deltaNone = frameDelta(renderChecked(none), 8);
        double deltaTaa = frameDelta(renderChecked(taa), 8);
        std::printf("%s still: flicker no AA %.3f, TAA %.3f levels\n", modeName(mode), deltaNone,
                    deltaTaa);
        EXPECT_GT(deltaNone, 0.0) << modeName(mode) << ": jitter should move aliased edges";
        EXPECT_LE(deltaTaa, 0.5 * deltaNone)
            << modeName(mode) << ": TAA " << deltaTaa << " levels, no AA " << deltaNone;
    }
}

// --aa-frames: a still accumulates that many jittered frames (measured 22.3 dB one frame,
// 32.6 dB 16 frames, forward); it needs TAA and one frame.
TEST(Taa, AaFramesStillIsCloserToSupersamplingThanOneFrame) {
    RenderOptions reference = renderOptions("builtin:default", RenderMode::Forward, kW, kH);
    reference.progress = false;
    reference.ssaa = 8;
    RenderRun ssaa = renderChecked(reference);
    RenderOptions one = reference;
    one.ssaa = 1;
    one.aa = AntiAliasing::None;
    RenderOptions still = one;
    still.aa = AntiAliasing::Taa;
    still.aaFrames = 16;
    RenderRun oneRun = renderChecked(one), stillRun = renderChecked(still);
    double psnrOne = psnr(oneRun.frames[0].rgba, ssaa.frames[0].rgba);
    double psnrStill = psnr(stillRun.frames[0].rgba, ssaa.frames[0].rgba);
    std::printf("still: one frame %.2f dB, 16 frames %.2f dB\n", psnrOne, psnrStill);
    EXPECT_GE(psnrStill, psnrOne + 9.0)
        << "16-frame still " << psnrStill << " dB, one frame " << psnrOne << " dB";
    EXPECT_EQ(stillRun.stats["taa"]["frames_accumulated"].get<uint32_t>(), 16u);
    RenderOptions bad = still;
    bad.frames = 2;
    EXPECT_THROW(runRender(sharedGpu(), bad), InputError);
    RenderOptions traced = one;
    traced.mode = RenderMode::Reference; // the path tracer averages its own jittered samples
    traced.aa = AntiAliasing::Taa;
    EXPECT_THROW(runRender(sharedGpu(), traced), InputError);
}

// A glowing cube slides across a dark wall before a still camera (0.375 m, ~13 pixels, a
// frame): the wall where it was shows no trace of it. The object has no motion vectors (only
// the camera's are computed): the depth test rejects the history where the cube was. Measured:
// no pixel of the ~7000 behind it over 8 frames is more than 5 (forward) / 6 (decoupled) levels
// brighter than the 4x4 SSAA reference, its edge's own aliasing; a trail would be the cube's
// ~200 levels fading by 0.9 a frame.
TEST(Taa, MovingObjectLeavesNoTrail) {
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        RenderOptions o = renderOptions(writeMovingCubeScene("taa_moving_cube"), mode, kW, kH);
        o.progress = false;
        o.frames = 12;
        o.time = 0.0;
        o.timeStep = 0.125;
        o.cameraOverrides.from = glm::vec3(0.0f, 1.5f, 9.0f);
        o.cameraOverrides.lookAt = glm::vec3(0.0f, 1.5f, 0.0f);
        RenderOptions reference = o;
        reference.mode = RenderMode::Forward;
        reference.ssaa = 4;
        reference.aa = AntiAliasing::None;
        o.aa = AntiAliasing::Taa;
        RenderRun ref = renderChecked(reference), taa = renderChecked(o);
        int worst = 0;
        size_t trailPixels = 0;
        for (size_t f = 4; f < o.frames; ++f) {
            size_t pixels = 0;
            worst = std::max(worst, worstTrail(taa, ref, f, pixels));
            trailPixels += pixels;
        }
        std::printf("%s moving cube: worst trail %d levels over %zu pixels\n", modeName(mode),
                    worst, trailPixels);
        EXPECT_GT(trailPixels, 1000u) << "the cube should sweep over the wall";
        EXPECT_LE(worst, 7) << modeName(mode) << ": a pixel behind the cube is " << worst
                            << " levels brighter than the reference (" << trailPixels
                            << " trail pixels)";
    }
}

} // namespace shadel::test
