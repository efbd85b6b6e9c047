// The visibility buffer (--marking visibility) against the raster marking + reconstruction it
// replaces: same chunks marked, same image within rounding, its passes named in the frame, and
// the debug views working in both modes. (Every test of test_decoupled.cpp also runs in both
// modes.)
#include "gpu_test_env.h"

#include <algorithm>
#include <cmath>

using namespace shadel;
using namespace shadel::test;

namespace {

RenderOptions decoupled(const std::string& scene, MarkingMode marking, uint32_t w, uint32_t h) {
    RenderOptions o = renderOptions(scene, RenderMode::Decoupled, w, h);
    o.marking = marking;
    return o;
}

uint64_t stat(const RenderRun& run, const char* name) {
    return run.stats[name].get<uint64_t>();
}

std::vector<std::string> passNames(const RenderRun& run) {
    std::vector<std::string> names;
    for (const auto& p : run.frames.front().passes) names.push_back(p.name);
    return names;
}

bool has(const std::vector<std::string>& names, const char* name) {
    return std::find(names.begin(), names.end(), name) != names.end();
}

} // namespace

// The compute marking rebuilds the shadel UV and its derivatives analytically; the raster path
// takes them from interpolation and dFdx. They must pick the same MIPs and mark the same chunks
// (up to LOD ties at the last bit), and the images must agree to rounding.
// Decoupled frames at 320x180 against their 8x8 SSAA forward render, 1.5 dB below the measured
// figures (both marking modes): builtin:default 32.78 dB, builtin:smooth 39.61 dB.
constexpr double kDefaultVsSsaa = 31.3;
constexpr double kSmoothVsSsaa = 38.1;

TEST(Visibility, MatchesRasterMarkingAndReconstruction) {
    for (const std::string scene : {"builtin:default", "builtin:smooth"}) {
        for (auto [w, h] : {std::pair{320u, 180u}, std::pair{960u, 540u}}) {
            RenderRun raster = renderChecked(decoupled(scene, MarkingMode::Raster, w, h));
            RenderRun vis = renderChecked(decoupled(scene, MarkingMode::Visibility, w, h));
            double p = psnr(vis.frames[0].rgba, raster.frames[0].rgba);
            double requestedRaster = double(stat(raster, "chunks_requested"));
            double requestedVis = double(stat(vis, "chunks_requested"));
            std::printf("[ figures ] %s %ux%u: PSNR(visibility, raster) = %.2f dB, chunks "
                        "requested %.0f vs %.0f\n",
                        scene.c_str(), w, h, p, requestedVis, requestedRaster);
            EXPECT_GE(p, 45.0) << scene << " " << w << "x" << h;
            if (w == 320) { // and both against the 8x8 supersampled forward render
                RenderOptions ref = decoupled(scene, MarkingMode::Raster, w, h);
                ref.mode = RenderMode::Forward;
                ref.ssaa = 8;
                RenderRun reference = renderChecked(ref);
                double pv = psnr(vis.frames[0].rgba, reference.frames[0].rgba);
                double pr = psnr(raster.frames[0].rgba, reference.frames[0].rgba);
                std::printf("[ figures ] %s %ux%u vs 8x8 SSAA: visibility %.2f dB, raster %.2f "
                            "dB\n",
                            scene.c_str(), w, h, pv, pr);
                const double floor = scene == "builtin:default" ? kDefaultVsSsaa : kSmoothVsSsaa;
                EXPECT_GE(pv, floor) << scene << ": measured " << pv;
                EXPECT_GE(pr, floor) << scene << ": measured " << pr;
            }
            // Same derivatives up to rounding: same MIPs, so the same chunks (lavapipe: exactly;
            // the margin is for LOD ties at the last bit on other drivers).
            EXPECT_LE(std::abs(requestedVis - requestedRaster), 0.0005 * requestedRaster + 1.0)
                << scene << " " << w << "x" << h;
            EXPECT_EQ(stat(vis, "reconstruction_misses"), 0u) << scene;
            EXPECT_EQ(stat(raster, "reconstruction_misses"), 0u) << scene;
            EXPECT_EQ(stat(vis, "pixels_covered"), stat(raster, "pixels_covered")) << scene;
            EXPECT_EQ(stat(vis, "reconstructed_pixels_sampled"),
                      stat(raster, "reconstructed_pixels_sampled"))
                << scene;
            // Marking's later passes both ran (shaders/shadel/mark_quad.glsl): quads on two
            // triangles of an instance, marked without per-pixel code, and the per-pixel rest.
            // The comparisons above hold only if every pass marks its quads as the raster path.
            uint64_t twoTriangles = vis.stats["marking_listed_quads"]["two_triangles"];
            uint64_t perPixel = vis.stats["marking_listed_quads"]["per_pixel"];
            std::printf("[ figures ] %s %ux%u: listed quads: %llu on two triangles, %llu per "
                        "pixel\n",
                        scene.c_str(), w, h, (unsigned long long)twoTriangles,
                        (unsigned long long)perPixel);
            EXPECT_GT(twoTriangles, 0u) << scene;
            EXPECT_GT(perPixel, 0u) << scene;
            EXPECT_FALSE(raster.stats.contains("marking_listed_quads")) << scene;
        }
    }
}

// Marking's first pass marks quads on one triangle and lists the rest (silhouettes, and at an
// odd size the quads the last column and row cut in half) for its later passes: every pixel of
// every kind must get its chunks and address, so odd sizes match the raster path too.
TEST(Visibility, OddSizesMarkTheLastColumnAndRow) {
    for (auto [w, h] : {std::pair{97u, 55u}, std::pair{161u, 90u}}) {
        RenderRun raster = renderChecked(decoupled("builtin:default", MarkingMode::Raster, w, h));
        RenderRun vis = renderChecked(decoupled("builtin:default", MarkingMode::Visibility, w, h));
        EXPECT_EQ(stat(vis, "reconstruction_misses"), 0u) << w << "x" << h;
        EXPECT_EQ(stat(vis, "pixels_covered"), stat(raster, "pixels_covered")) << w << "x" << h;
        EXPECT_GE(psnr(vis.frames[0].rgba, raster.frames[0].rgba), 45.0) << w << "x" << h;
        // The last column and row themselves, not only the image as a whole.
        const std::vector<uint8_t>& a = vis.frames[0].rgba;
        const std::vector<uint8_t>& b = raster.frames[0].rgba;
        int worst = 0;
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                if (x != w - 1 && y != h - 1) continue;
                for (int c = 0; c < 3; ++c)
                    worst = std::max(
                        worst, std::abs(int(a[(y * w + x) * 4 + c]) - int(b[(y * w + x) * 4 + c])));
            }
        EXPECT_LE(worst, 8) << w << "x" << h << ": the edge pixels differ from the raster path";
    }
}

// With --ssaa the targets are N x N larger; the compute passes cover the internal resolution.
TEST(Visibility, SupersampledTargetsAreCoveredByTheComputePasses) {
    RenderOptions o = decoupled("builtin:smooth", MarkingMode::Visibility, 96, 54);
    o.ssaa = 2;
    RenderRun vis = renderChecked(o);
    o.marking = MarkingMode::Raster;
    RenderRun raster = renderChecked(o);
    EXPECT_EQ(stat(vis, "reconstruction_misses"), 0u);
    EXPECT_GE(psnr(vis.frames[0].rgba, raster.frames[0].rgba), 45.0);
}

// The frame shows which path ran: one raster pass over the scene (the visibility prepass) and
// compute marking + resolve, or the three raster passes.
TEST(Visibility, PassesAreNamedPerMode) {
    auto vis =
        passNames(renderChecked(decoupled("builtin:smooth", MarkingMode::Visibility, 64, 36)));
    auto raster =
        passNames(renderChecked(decoupled("builtin:smooth", MarkingMode::Raster, 64, 36)));
    for (const char* name :
         {"visibilityPrepass", "markingCompute", "resolveCompute", "hybridForward"}) {
        EXPECT_TRUE(has(vis, name)) << name;
        EXPECT_FALSE(has(raster, name)) << name;
    }
    for (const char* name : {"depthPrepass", "marking", "reconstruction"}) {
        EXPECT_TRUE(has(raster, name)) << name;
        EXPECT_FALSE(has(vis, name)) << name;
    }
}

// The debug views are drawn by the resolve in visibility mode: each view matches the raster
// path's (the marking view and the MIP heat map closely; chunk lines from analytic fwidth).
TEST(Visibility, DebugViewsMatchRasterMode) {
    for (Visualize v : {Visualize::Marking, Visualize::Mips, Visualize::Chunks, Visualize::Sheet}) {
        RenderOptions o = decoupled("builtin:default", MarkingMode::Visibility, 160, 90);
        o.visualize = v;
        RenderRun vis = renderChecked(o);
        o.marking = MarkingMode::Raster;
        RenderRun raster = renderChecked(o);
        double p = psnr(vis.frames[0].rgba, raster.frames[0].rgba);
        std::printf("[ figures ] --visualize %u: PSNR(visibility, raster) = %.2f dB\n", uint32_t(v),
                    p);
        EXPECT_GE(p, 30.0) << "view " << uint32_t(v);
    }
}

// --marking auto (the default) takes the visibility buffer, and the raster path where a feature
// needs its depth-only prepass (occlusion culling's phase 2, the screen-space thin G-buffer);
// the stats say which ran. (Transparency with either path:
// Oit.DecoupledTransparencyMatchesForward.)
TEST(Visibility, AutoMarkingPicksVisibilityUnlessAFeatureNeedsRaster) {
    RenderOptions o = decoupled("builtin:smooth", MarkingMode::Auto, 64, 36);
    RenderRun automatic = renderChecked(o);
    EXPECT_EQ(automatic.stats["marking"], "visibility");
    EXPECT_TRUE(has(passNames(automatic), "resolveCompute"));
    o.occlusion = true;
    EXPECT_EQ(renderChecked(o).stats["marking"], "raster");
    o.occlusion = false;
    o.screenSpace = true;
    RenderRun screenSpace = renderChecked(o);
    EXPECT_EQ(screenSpace.stats["marking"], "raster");
    EXPECT_TRUE(has(passNames(screenSpace), "reconstruction"));
}
