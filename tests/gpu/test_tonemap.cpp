// The tonemap fused into the opaque shading pass (--fuse-tonemap, render/post/tonemap.h): where
// nothing draws into the scene colour after it, forward shading and the decoupled compute resolve
// write the display pixels themselves. The image must be the separate pass's to within one level
// (the fused passes skip the scene colour's half-float rounding), with the same coverage, and
// every frame where something draws after the opaque pass must keep the separate pass.
#include "gpu_test_env.h"

#include <algorithm>
#include <cstdlib>

using namespace shadel;
using namespace shadel::test;

namespace {

bool ranPass(const RenderRun& run, const char* name) {
    const auto& passes = run.frames.back().passes;
    return std::any_of(passes.begin(), passes.end(),
                       [&](const PassTiming& p) { return p.name == name; });
}

RenderRun render(RenderOptions o, bool fuse) {
    o.fuseTonemap = fuse;
    return renderChecked(o);
}

// Every frame's coverage the same, and every colour channel within one level.
void expectSameImage(const RenderRun& fused, const RenderRun& separate) {
    ASSERT_EQ(fused.frames.size(), separate.frames.size());
    EXPECT_EQ(fused.stats["pixels_covered"], separate.stats["pixels_covered"]);
    int worst = 0;
    for (size_t f = 0; f < fused.frames.size(); ++f) {
        const std::vector<uint8_t>& a = fused.frames[f].rgba;
        const std::vector<uint8_t>& b = separate.frames[f].rgba;
        ASSERT_EQ(a.size(), b.size());
        for (size_t i = 0; i < a.size(); ++i) {
            if (i % 4 == 3)
                ASSERT_EQ(a[i], b[i]) << "coverage of frame " << f << ", pixel " << i / 4;
            else
                worst = std::max(worst, std::abs(int(a[i]) - int(b[i])));
        }
    }
    EXPECT_LE(worst, 1);
}

} // namespace

// Forward: display colour into an RGBA8 target, copied into the readback.
TEST(Tonemap, FusedForwardMatchesTheSeparatePass) {
    RenderOptions o = renderOptions("builtin:default", RenderMode::Forward, 160, 90);
    o.frames = 2;
    o.cameraPath = CameraPath::Orbit;
    RenderRun fused = render(o, true), separate = render(o, false);
    EXPECT_FALSE(ranPass(fused, "tonemap"));
    EXPECT_TRUE(ranPass(fused, "displayReadback"));
    EXPECT_TRUE(ranPass(separate, "tonemap"));
    EXPECT_FALSE(ranPass(separate, "displayReadback"));
    EXPECT_EQ(fused.stats["tonemap_fused_frames"].get<uint32_t>(), 2u);
    EXPECT_EQ(separate.stats["tonemap_fused_frames"].get<uint32_t>(), 0u);
    expectSameImage(fused, separate);
}

// Decoupled: the resolve writes every pixel as the display shows it, forward (hybrid) instances
// read from the scene colour the raster pass drew before it (builtin:many has hundreds of them),
// and the debug views, drawn by the resolve too.
TEST(Tonemap, FusedResolveMatchesTheSeparatePass) {
    for (Visualize view : {Visualize::None, Visualize::Reuse}) {
        RenderOptions o = renderOptions("builtin:many", RenderMode::Decoupled, 160, 90);
        o.frames = 2;
        o.cameraPath = CameraPath::Orbit;
        o.marking = MarkingMode::Visibility;
        o.visualize = view;
        RenderRun fused = render(o, true), separate = render(o, false);
        SCOPED_TRACE(int(view));
        EXPECT_GT(fused.stats["objects_forward"].get<uint32_t>(), 0u);
        EXPECT_FALSE(ranPass(fused, "tonemap"));
        EXPECT_FALSE(ranPass(fused, "displayReadback"));
        EXPECT_TRUE(ranPass(separate, "tonemap"));
        EXPECT_EQ(fused.stats["tonemap_fused_frames"].get<uint32_t>(), 2u);
        expectSameImage(fused, separate);
    }
}

// Blended materials (drawn after the opaque pass), supersampling (the tonemap pass averages the
// samples) and the raster reconstruction keep the separate pass.
TEST(Tonemap, SeparateWhereAPassDrawsAfterTheOpaqueOne) {
    RenderOptions blended = renderOptions("builtin:transparency", RenderMode::Forward, 96, 64);
    RenderOptions supersampled = renderOptions("builtin:default", RenderMode::Forward, 64, 36);
    supersampled.ssaa = 2;
    RenderOptions raster = renderOptions("builtin:default", RenderMode::Decoupled, 64, 36);
    raster.marking = MarkingMode::Raster;
    for (const RenderOptions& o : {blended, supersampled, raster}) {
        RenderRun run = render(o, true);
        SCOPED_TRACE(o.scene);
        EXPECT_TRUE(ranPass(run, "tonemap"));
        EXPECT_EQ(run.stats["tonemap_fused_frames"].get<uint32_t>(), 0u);
    }
}
