// Projected box decals (render/decals, shaders/decals) on builtin:decals: they change the image
// where their boxes are and nowhere else, the AO-only kind darkens the ambient light alone, and
// the shadel path (decals applied per shadel from per-chunk lists) matches forward shading.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <sys/wait.h>

#include "common/print_labels.h"
#include "gpu_test_env.h"
#include "render/camera.h"
#include "render/debug/inspect.h"
#include "scene/builtin_decals.h"
#include "scene/load.h"

using namespace shadel;
using namespace shadel::test;

namespace {

constexpr uint32_t kW = 320, kH = 180;

RenderOptions decalOptions(RenderMode mode, bool decals) {
    RenderOptions o = renderOptions("builtin:decals", mode, kW, kH);
    o.decals = decals;
    o.progress = false;
    return o;
}

struct Rect {
    int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1; // inclusive pixel bounds
    bool contains(int x, int y) const { return x >= x0 && x <= x1 && y >= y0 && y <= y1; }
};

// The screen rectangle of a decal's box (its 8 corners projected), grown by `margin` pixels.
Rect screenRect(const Decal& d, const CameraView& view, int margin) {
    glm::vec3 z = glm::normalize(d.axisZ);
    glm::vec3 x = glm::normalize(d.axisX - z * glm::dot(z, d.axisX));
    glm::vec3 y = glm::cross(z, x);
    Rect r;
    for (int i = 0; i < 8; ++i) {
        glm::vec3 p = d.center + x * d.size.x * ((i & 1) ? 0.5f : -0.5f) +
                      y * d.size.y * ((i & 2) ? 0.5f : -0.5f) +
                      z * d.size.z * ((i & 4) ? 0.5f : -0.5f);
        glm::vec4 c = view.proj * view.view * glm::vec4(p, 1.0f);
        glm::vec2 px = (glm::vec2(c) / c.w * 0.5f + 0.5f) * glm::vec2(kW, kH);
        r.x0 = std::min(r.x0, int(std::floor(px.x)) - margin);
        r.y0 = std::min(r.y0, int(std::floor(px.y)) - margin);
        r.x1 = std::max(r.x1, int(std::ceil(px.x)) + margin);
        r.y1 = std::max(r.y1, int(std::ceil(px.y)) + margin);
    }
    return r;
}

glm::ivec2 projectPixel(glm::vec3 p, const CameraView& view) {
    glm::vec4 c = view.proj * view.view * glm::vec4(p, 1.0f);
    glm::vec2 px = (glm::vec2(c) / c.w * 0.5f + 0.5f) * glm::vec2(kW, kH);
    return glm::ivec2(px);
}

int pixelDelta(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, size_t i) {
    int d = 0;
    for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a[i * 4 + c]) - int(b[i * 4 + c])));
    return d;
}

std::map<uint32_t, std::vector<ShaderPrint>> inspect(bool decals, glm::ivec2 pixel) {
    RenderOptions o = decalOptions(RenderMode::Forward, decals);
    o.inspectX = pixel.x;
    o.inspectY = pixel.y;
    RenderRun run = renderChecked(o);
    std::map<uint32_t, std::vector<ShaderPrint>> byLabel;
    for (const ShaderPrint& s : frontFragment(run.frames.back().prints).prints)
        byLabel[s.label].push_back(s);
    return byLabel;
}

glm::vec3 f3(const std::map<uint32_t, std::vector<ShaderPrint>>& p, uint32_t label, size_t i = 0) {
    const ShaderPrint& s = p.at(label).at(i);
    return {s.f(0), s.f(1), s.f(2)};
}

} // namespace

// Every decal changes the pixels under its box (each kind: base colour, normal, roughness, AO),
// and not one pixel outside the boxes changes.
TEST(Decals, OnAndOffDifferUnderTheDecalsOnly) {
    RenderRun on = renderChecked(decalOptions(RenderMode::Forward, true));
    RenderRun off = renderChecked(decalOptions(RenderMode::Forward, false));
    Scene scene = loadScene("builtin:decals", {});
    ASSERT_GE(scene.decals.size(), 4u);
    CameraView view = makeCameraView(findCamera(scene, ""), kW, kH);
    std::vector<Rect> rects;
    for (const Decal& d : scene.decals) rects.push_back(screenRect(d, view, 2));
    const auto& a = on.frames[0].rgba;
    const auto& b = off.frames[0].rgba;
    size_t outsideChanged = 0, insideChanged = 0;
    std::vector<size_t> changedPerDecal(rects.size(), 0);
    for (int y = 0; y < int(kH); ++y) {
        for (int x = 0; x < int(kW); ++x) {
            int d = pixelDelta(a, b, size_t(y) * kW + x);
            bool inside = false;
            for (size_t k = 0; k < rects.size(); ++k) {
                if (!rects[k].contains(x, y)) continue;
                inside = true;
                if (d > 2) changedPerDecal[k]++;
            }
            if (d > 0 && !inside) outsideChanged++;
            if (d > 2 && inside) insideChanged++;
        }
    }
    std::printf("[ figures ] decals on vs off at %ux%u: %zu pixels changed under the decals, %zu "
                "outside; per decal:",
                kW, kH, insideChanged, outsideChanged);
    for (size_t n : changedPerDecal) std::printf(" %zu", n);
    std::printf("; PSNR on vs off %.2f dB\n", psnr(a, b));
    EXPECT_EQ(outsideChanged, 0u) << "a decal changed pixels outside every decal's box";
    EXPECT_GT(insideChanged, size_t(kW * kH / 50)) << "decals barely visible";
    for (size_t k = 0; k < rects.size(); ++k)
        EXPECT_GT(changedPerDecal[k], 10u) << "decal " << k << " changed nothing visible";
    // Stats: every decal is in the scene and in the camera's view; lists were built per tile.
    EXPECT_EQ(on.stats["decals"].get<uint32_t>(), scene.decals.size());
    EXPECT_EQ(on.stats["decals_visible"].get<uint32_t>(), scene.decals.size());
    EXPECT_GT(on.stats["decal_tile_pairs"].get<uint32_t>(), scene.decals.size());
    EXPECT_EQ(on.stats["decal_lists_overflowed"].get<uint32_t>(), 0u);
    EXPECT_EQ(off.stats["decals"].get<uint32_t>(), 0u);
}

// Seed 001's character shadow: the AO-only decal under the figure lowers the ambient term and
// leaves the base colour, the sun and the lamp exactly as they were; the pixel darkens by what
// the ambient lost.
TEST(Decals, AmbientOcclusionDecalDarkensOnlyTheAmbientLight) {
    Scene scene = loadScene("builtin:decals", {});
    CameraView view = makeCameraView(findCamera(scene, ""), kW, kH);
    // Beside the figure's base (on the ground, inside the contact shadow).
    glm::ivec2 pixel =
        projectPixel(decalsSceneContactShadowCentre() + glm::vec3(0.0f, 0.0f, 0.4f), view);
    auto on = inspect(true, pixel);
    auto off = inspect(false, pixel);
    ASSERT_TRUE(on.count(PRINT_AMBIENT) && off.count(PRINT_AMBIENT)) << "nothing inspected";
    ASSERT_EQ(on.at(PRINT_INSTANCE)[0].u(0), off.at(PRINT_INSTANCE)[0].u(0));
    glm::vec3 ambientOn = f3(on, PRINT_AMBIENT), ambientOff = f3(off, PRINT_AMBIENT);
    std::printf("[ figures ] AO decal at pixel %d,%d: ambient %.4f -> %.4f (green)\n", pixel.x,
                pixel.y, ambientOff.g, ambientOn.g);
    EXPECT_LT(ambientOn.g, 0.7f * ambientOff.g) << "the AO decal should darken the ambient term";
    EXPECT_GT(ambientOn.g, 0.0f);
    EXPECT_EQ(f3(on, PRINT_BASE_COLOR), f3(off, PRINT_BASE_COLOR));
    EXPECT_EQ(on.at(PRINT_OCCLUSION)[0].f(0), off.at(PRINT_OCCLUSION)[0].f(0));
    ASSERT_TRUE(on.count(PRINT_SUN) && off.count(PRINT_SUN));
    EXPECT_EQ(f3(on, PRINT_SUN), f3(off, PRINT_SUN)) << "the sun must not be occluded";
    ASSERT_EQ(on.count(PRINT_LIGHT), off.count(PRINT_LIGHT));
    size_t lights = on.count(PRINT_LIGHT) ? on.at(PRINT_LIGHT).size() : 0;
    ASSERT_EQ(lights, off.count(PRINT_LIGHT) ? off.at(PRINT_LIGHT).size() : 0);
    for (size_t i = 0; i < lights; ++i)
        EXPECT_EQ(f3(on, PRINT_LIGHT, i), f3(off, PRINT_LIGHT, i)) << "light " << i;
    glm::vec3 shadedDrop = f3(off, PRINT_SHADED) - f3(on, PRINT_SHADED);
    glm::vec3 ambientDrop = ambientOff - ambientOn;
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(shadedDrop[c], ambientDrop[c], 1e-4f + 1e-3f * ambientDrop[c])
            << "the pixel darkens by the ambient it lost, nothing else";
}

// The shadel path applies decals per shadel from its object's list narrowed to the shadel: the
// image matches forward shading, nothing is missed, and those lists are what put the decals
// there; the per-object pass keeps only the decals meeting an object (not every pair).
TEST(Decals, DecoupledMatchesForward) {
    RenderRun forward = renderChecked(decalOptions(RenderMode::Forward, true));
    RenderRun forwardOff = renderChecked(decalOptions(RenderMode::Forward, false));
    RenderRun decoupled = renderChecked(decalOptions(RenderMode::Decoupled, true));
    double p = psnr(decoupled.frames[0].rgba, forward.frames[0].rgba);
    double pOff = psnr(decoupled.frames[0].rgba, forwardOff.frames[0].rgba);
    std::printf("[ figures ] builtin:decals %ux%u: decoupled vs forward %.2f dB, misses %u, "
                "decal shadel pairs %u, tile pairs %u; decoupled vs forward without decals "
                "%.2f dB\n",
                kW, kH, p, decoupled.stats["reconstruction_misses"].get<uint32_t>(),
                decoupled.stats["decal_shadel_pairs"].get<uint32_t>(),
                decoupled.stats["decal_tile_pairs"].get<uint32_t>(), pOff);
    EXPECT_GE(p, 35.0);
    EXPECT_EQ(decoupled.stats["reconstruction_misses"].get<uint32_t>(), 0u);
    EXPECT_GT(decoupled.stats["decal_shadel_pairs"].get<uint32_t>(), 0u);
    const uint32_t objectPairs = decoupled.stats["decal_object_pairs"].get<uint32_t>();
    const uint32_t allPairs = decoupled.stats["decals_in_frustum"].get<uint32_t>() *
                              decoupled.stats["objects_decoupled"].get<uint32_t>();
    std::printf("[ figures ] (decal, object) pairs %u of %u\n", objectPairs, allPairs);
    EXPECT_GT(objectPairs, 0u);
    EXPECT_LT(objectPairs, allPairs) << "the per-object pass must cull";
    EXPECT_EQ(decoupled.stats["decals_visible"].get<uint32_t>(),
              decoupled.stats["decals"].get<uint32_t>());
    EXPECT_LT(pOff, p - 10.0) << "the shadel path must show the decals as forward does";
}

TEST(Decals, BadDecalsFlagIsOneLineAndExitCode2) {
    std::string errFile = tempPath("decals_stderr.txt");
    std::string cmd = std::string("timeout 60 ") + SHADEL_BINARY +
                      " render --scene builtin:decals --size 64x36 --decals maybe >/dev/null 2>" +
                      errFile;
    int status = std::system(cmd.c_str());
    std::ifstream in(errFile);
    std::stringstream ss;
    ss << in.rdbuf();
    std::string err = ss.str();
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 2);
    EXPECT_NE(err.find("--decals"), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
}
