// Seed 004's stencil-culled effects (render/stencil): the water composite and the character
// outline with occlusion tint run only on their stencil pixels, and give the image their
// full-screen versions give; the outline shows a character hidden behind a wall.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <sys/wait.h>

#include <glm/gtc/matrix_transform.hpp>

#include "gpu_test_env.h"
#include "render/stencil/screen_rects.h"

using namespace shadel;
using namespace shadel::test;

namespace {

RenderOptions arenaEffects(StencilEffects effects) {
    RenderOptions o = renderOptions("builtin:arena", RenderMode::Forward, 320, 180);
    o.screenSpace = true;
    o.stencilEffects = effects;
    o.progress = false;
    return o;
}

// From behind the tallest stand, looking at the ring: every fighter is hidden by the stands.
RenderOptions behindTheStands(StencilEffects effects) {
    RenderOptions o = arenaEffects(effects);
    o.cameraOverrides.from = glm::vec3(0.0f, 1.6f, -26.0f);
    o.cameraOverrides.lookAt = glm::vec3(0.0f, 1.2f, 0.0f);
    return o;
}

uint64_t pixelsDiffering(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
    uint64_t n = 0;
    for (size_t i = 0; i + 3 < a.size(); i += 4)
        if (std::abs(int(a[i]) - int(b[i])) + std::abs(int(a[i + 1]) - int(b[i + 1])) +
                std::abs(int(a[i + 2]) - int(b[i + 2])) >
            6)
            ++n;
    return n;
}

} // namespace

// The stencil only culls: the culled passes equal the full-screen ones that branch per pixel,
// from the main camera (water and fighters in view) and from behind the stands.
TEST(StencilEffects, StencilCulledMatchesFullScreen) {
    for (bool hidden : {false, true}) {
        RenderRun culled = renderChecked(hidden ? behindTheStands(StencilEffects::On)
                                                : arenaEffects(StencilEffects::On));
        RenderRun full = renderChecked(hidden ? behindTheStands(StencilEffects::FullScreen)
                                              : arenaEffects(StencilEffects::FullScreen));
        RenderRun off = renderChecked(hidden ? behindTheStands(StencilEffects::Off)
                                             : arenaEffects(StencilEffects::Off));
        double p = psnr(culled.frames[0].rgba, full.frames[0].rgba);
        uint64_t changed = pixelsDiffering(culled.frames[0].rgba, off.frames[0].rgba);
        std::printf("arena 320x180 %s: stencil vs full-screen %.2f dB; %llu pixels changed by "
                    "the effects\n",
                    hidden ? "behind the stands" : "main camera", p, (unsigned long long)changed);
        EXPECT_GE(p, 50.0);
        // The effects do something, on a part of the image only.
        EXPECT_GT(changed, 40u);
        EXPECT_LT(changed, 320u * 180u / 4u);
    }
}

// Behind the stands no fighter is visible (and no water), so the pixels the effects change are
// the outline (bright, warm) and the occlusion tint (cold) of the hidden fighters, drawn
// over the stand in front of them.
TEST(StencilEffects, OutlineShowsACharacterBehindAWall) {
    RenderRun on = renderChecked(behindTheStands(StencilEffects::On));
    RenderRun off = renderChecked(behindTheStands(StencilEffects::Off));
    const auto& a = on.frames[0].rgba;
    const auto& b = off.frames[0].rgba;
    uint64_t changed = 0, outline = 0, tinted = 0;
    for (size_t i = 0; i + 3 < a.size(); i += 4) {
        if (std::abs(int(a[i]) - int(b[i])) + std::abs(int(a[i + 1]) - int(b[i + 1])) +
                std::abs(int(a[i + 2]) - int(b[i + 2])) <=
            6)
            continue;
        ++changed;
        // The outline is bright and warm (tonemapped to a pale yellow), the tint cold.
        if (a[i] > 220 && a[i + 1] > 200 && a[i + 2] + 40 < a[i]) ++outline;
        if (a[i + 2] > a[i] + 40 && a[i + 2] > b[i + 2] + 10) ++tinted;
    }
    std::printf("behind the stands 320x180: %llu pixels changed, %llu outline, %llu tinted\n",
                (unsigned long long)changed, (unsigned long long)outline,
                (unsigned long long)tinted);
    EXPECT_GT(outline, 20u);
    EXPECT_GT(tinted, 5u);
    EXPECT_GE(outline + tinted, changed * 9 / 10);
    EXPECT_LT(changed, 320u * 180u / 20u);
}

// The bounded draw (triangles scissored to the rects of the instances' projected boxes) gives the
// image of the unbounded one (one triangle over the whole target, the stencil test alone
// culling), byte for byte: from the main camera, behind the stands, close to the fighters
// (some partly off-screen) and from inside a fighter's boxes (they straddle the camera plane).
TEST(StencilEffects, BoundedDrawEqualsFullScreenStencilDraw) {
    struct View {
        const char* name;
        RenderOptions (*options)(StencilEffects);
    };
    const View views[] = {
        {"main camera", arenaEffects},
        {"behind the stands", behindTheStands},
        {"fighters camera",
         [](StencilEffects e) {
             RenderOptions o = arenaEffects(e);
             o.camera = "fighters";
             return o;
         }},
        {"inside fighter 3",
         [](StencilEffects e) {
             RenderOptions o = arenaEffects(e);
             o.cameraOverrides.from = glm::vec3(-3.0f, 1.2f, 7.45f);
             o.cameraOverrides.lookAt = glm::vec3(0.0f, 1.2f, 0.0f);
             return o;
         }},
    };
    for (const View& v : views) {
        RenderRun bounded = renderChecked(v.options(StencilEffects::On));
        RenderRun unbounded = renderChecked(v.options(StencilEffects::OnUnbounded));
        RenderRun off = renderChecked(v.options(StencilEffects::Off));
        const auto& a = bounded.frames[0].rgba;
        const auto& b = unbounded.frames[0].rgba;
        size_t differing = 0;
        for (size_t i = 0; i < a.size(); ++i) differing += a[i] != b[i];
        uint64_t changed = pixelsDiffering(b, off.frames[0].rgba);
        std::printf("arena 320x180 %s: bounded vs unbounded %zu bytes differ, %.2f dB; %llu "
                    "pixels changed by the effects\n",
                    v.name, differing, psnr(a, b), (unsigned long long)changed);
        ASSERT_EQ(a.size(), b.size());
        EXPECT_EQ(differing, 0u) << v.name;
        EXPECT_GT(changed, 40u) << v.name; // the effects are on screen in every view
    }
}

// The rects the bounded draw uses are disjoint (the effects write the scene colour in place, a
// pixel covered twice would get the effect twice) and cover exactly the union of the boxes'
// rects: random rects on a small grid, checked pixel by pixel.
TEST(StencilEffects, DisjointCoverIsExactAndDisjoint) {
    std::mt19937 rng(14);
    for (int round = 0; round < 200; ++round) {
        const int w = 48, h = 40;
        std::uniform_int_distribution<int> x(-4, w + 4), y(-4, h + 4), n(0, 12);
        std::vector<PixelRect> rects(size_t(n(rng)));
        for (PixelRect& r : rects) {
            r = {x(rng), y(rng), x(rng), y(rng)}; // some empty (x1 <= x0 or y1 <= y0)
            if (round % 2)
                r = {std::min(r.x0, r.x1), std::min(r.y0, r.y1), std::max(r.x0, r.x1),
                     std::max(r.y0, r.y1)};
        }
        std::vector<PixelRect> cover = disjointCover(rects);
        for (int py = -4; py < h + 4; ++py)
            for (int px = -4; px < w + 4; ++px) {
                auto inside = [&](const PixelRect& r) {
                    return !r.empty() && px >= r.x0 && px < r.x1 && py >= r.y0 && py < r.y1;
                };
                int inUnion = int(std::count_if(rects.begin(), rects.end(), inside) > 0);
                int inCover = int(std::count_if(cover.begin(), cover.end(), inside));
                ASSERT_EQ(inCover, inUnion) << "round " << round << " pixel " << px << "," << py;
            }
        for (const PixelRect& r : cover) EXPECT_FALSE(r.empty());
    }
}

// A box's rect: clamped to the target, empty off-screen or behind the camera, the whole target
// when it straddles the camera plane, and it holds every projected corner.
TEST(StencilEffects, ProjectedBoxRect) {
    glm::mat4 proj = glm::perspective(0.9f, 16.0f / 9.0f, 0.1f, 100.0f);
    glm::mat4 view = glm::lookAt(glm::vec3(0, 0, 5), glm::vec3(0), glm::vec3(0, 1, 0));
    glm::mat4 vp = proj * view;
    const int w = 320, h = 180;
    PixelRect centre = projectedBoxRect(vp, glm::vec3(-0.5f), glm::vec3(0.5f), w, h, 1);
    EXPECT_FALSE(centre.empty());
    EXPECT_GT(centre.x0, 0);
    EXPECT_LT(centre.x1, w);
    EXPECT_LT((centre.x1 - centre.x0) * (centre.y1 - centre.y0), w * h / 4);
    for (int c = 0; c < 8; ++c) {
        glm::vec4 clip = vp * glm::vec4((c & 1) ? 0.5f : -0.5f, (c & 2) ? 0.5f : -0.5f,
                                        (c & 4) ? 0.5f : -0.5f, 1.0f);
        glm::vec2 px = (glm::vec2(clip) / clip.w * 0.5f + 0.5f) * glm::vec2(w, h);
        EXPECT_GE(px.x, float(centre.x0));
        EXPECT_LE(px.x, float(centre.x1));
        EXPECT_GE(px.y, float(centre.y0));
        EXPECT_LE(px.y, float(centre.y1));
    }
    EXPECT_TRUE(projectedBoxRect(vp, glm::vec3(40, -1, -1), glm::vec3(42, 1, 1), w, h, 1).empty());
    EXPECT_TRUE(projectedBoxRect(vp, glm::vec3(-1, -1, 8), glm::vec3(1, 1, 9), w, h, 1).empty());
    EXPECT_EQ(projectedBoxRect(vp, glm::vec3(-1, -1, 4), glm::vec3(1, 1, 6), w, h, 1),
              (PixelRect{0, 0, w, h}));
    PixelRect edge =
        projectedBoxRect(vp, glm::vec3(2.0f, -0.5f, -0.5f), glm::vec3(9, 0.5f, 0.5f), w, h, 1);
    EXPECT_FALSE(edge.empty());
    EXPECT_EQ(edge.x1, w);
}

TEST(StencilEffects, BadFlagsAreInputErrors) {
    RenderOptions o = arenaEffects(StencilEffects::On);
    o.screenSpace = false;
    EXPECT_THROW(renderChecked(o), InputError);
    std::string cmd = std::string("timeout 60 ") + SHADEL_BINARY +
                      " render --size 16x16 --screen-space on --stencil-effects maybe "
                      ">/dev/null 2>&1";
    int status = std::system(cmd.c_str());
    EXPECT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 2);
}
