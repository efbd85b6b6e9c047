// Seed 004's stencil-culled effects (render/stencil): the water composite and the character
// outline with occlusion tint run only on their stencil pixels, and give the image their
// full-screen versions give; the outline shows a character hidden behind a wall.
#include <cstdio>
#include <cstdlib>
#include <sys/wait.h>

#include "gpu_test_env.h"

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
