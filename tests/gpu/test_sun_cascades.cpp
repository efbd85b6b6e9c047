// Cascaded sun shadows (render/lighting/sun_cascades.h): the view depth cut
// into slices, each with its own map, spends far more texels per metre near the camera than the
// one map fitted to the scene, still covers the view out to the scene's far end, changes the
// image only at shadow edges, and shades the decoupled path as the forward one (shared GLSL).
#include "gpu_test_env.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>

using namespace shadel;
using namespace shadel::test;

namespace {
RenderOptions cascadeOptions(RenderMode mode, uint32_t cascades) {
    RenderOptions o = renderOptions("builtin:default", mode, 192, 108);
    o.sunCascades = cascades;
    return o;
}
} // namespace

TEST(SunCascades, FinerTexelsNearTheCameraSameImageElsewhereBothPaths) {
    RenderRun one = renderChecked(cascadeOptions(RenderMode::Forward, 1));
    RenderRun four = renderChecked(cascadeOptions(RenderMode::Forward, 4));
    RenderRun fourDecoupled = renderChecked(cascadeOptions(RenderMode::Decoupled, 4));
    RenderRun oneDecoupled = renderChecked(cascadeOptions(RenderMode::Decoupled, 1));
    EXPECT_EQ(one.stats["sun_cascades"], 1);
    const auto& s = four.stats;
    ASSERT_EQ(s["sun_cascades"], 4);
    const auto& splits = s["sun_cascade_splits_m"];
    const auto& texels = s["sun_cascade_texel_m"];
    double wholeScene = s["sun_shadow_texel_m"].get<double>();
    ASSERT_EQ(splits.size(), 4u);
    for (size_t i = 1; i < 4; ++i) {
        EXPECT_GT(splits[i].get<double>(), splits[i - 1].get<double>());
        EXPECT_GE(texels[i].get<double>(), texels[i - 1].get<double>());
    }
    // The measured density: the nearest cascade's texels are several times finer than the
    // whole-scene map's (texel widths: x4 or more; texels per square metre: x16 or more).
    EXPECT_LE(texels[0].get<double>() * 4.0, wholeScene) << s.dump();
    EXPECT_GT(splits[3].get<double>(), 30.0) << "the last cascade reaches the far street";

    // The maps only move shadow edges: the images agree closely, yet differ.
    double change = psnr(one.frames[0].rgba, four.frames[0].rgba);
    EXPECT_GE(change, 30.0);
    EXPECT_LT(change, 80.0) << "the cascades are what the shading reads";
    // Decoupled vs forward agree as well with cascades as with one map (the shared GLSL).
    double agreeOne = psnr(one.frames[0].rgba, oneDecoupled.frames[0].rgba);
    double agreeFour = psnr(four.frames[0].rgba, fourDecoupled.frames[0].rgba);
    EXPECT_GE(agreeFour, agreeOne - 1.0) << agreeOne << " dB with one map";
}

TEST(SunCascades, PcssPerCascadeAndBadCountIsAnInputError) {
    RenderOptions o = cascadeOptions(RenderMode::Forward, 3);
    o.sunSoftShadows = true;
    RenderRun soft = renderChecked(o);
    o.sunSoftShadows = false;
    RenderRun hard = renderChecked(o);
    EXPECT_EQ(soft.stats["sun_cascades"], 3);
    // PCSS widens the penumbrae: a different image, close to the PCF one.
    double d = psnr(soft.frames[0].rgba, hard.frames[0].rgba);
    EXPECT_LT(d, 80.0);
    EXPECT_GE(d, 25.0);

    std::string err = (std::filesystem::temp_directory_path() / "shadel-cascades-err.txt").string();
    for (const char* args : {"--sun-cascades 5", "--sun-cascades 0", "--sun-cascades two"}) {
        std::string cmd = std::string("timeout 120 ") + SHADEL_BINARY +
                          " render --scene builtin:default --size 32x32 " + args +
                          " >/dev/null 2>" + err;
        int status = std::system(cmd.c_str());
        ASSERT_TRUE(WIFEXITED(status)) << args;
        EXPECT_EQ(WEXITSTATUS(status), 2) << args;
        std::ifstream in(err);
        std::stringstream text;
        text << in.rdbuf();
        std::string message = text.str();
        EXPECT_NE(message.find("--sun-cascades"), std::string::npos) << message;
        EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
    }
}
