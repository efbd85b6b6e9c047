// `shadel bench --plot FILE.png` (app/bench_plot.h): bars proportional to each mode's GPU ms.
#include "gpu_test_env.h"

#include <algorithm>
#include <filesystem>

#include "app/bench_plot.h"
#include "core/host.h"

using namespace shadel;
using namespace shadel::test;

namespace {

uint64_t pixelsOf(const PlotImage& img, const uint8_t c[3]) {
    uint64_t n = 0;
    for (size_t i = 0; i < img.rgba.size(); i += 4)
        n += img.rgba[i] == c[0] && img.rgba[i + 1] == c[1] && img.rgba[i + 2] == c[2];
    return n;
}

// One frame of a small smooth scene: the three modes in seconds.
BenchOptions smallBench() {
    BenchOptions b;
    b.scene = "builtin:smooth";
    b.width = 64;
    b.height = 36;
    b.frames = 1;
    return b;
}

} // namespace

// A synthetic bench result: each mode's bar area follows its summed pass times.
TEST(BenchPlot, BarAreasFollowThePassTimes) {
    nlohmann::json bench;
    bench["scene"] = "synthetic";
    bench["device"] = "none";
    const double ms[3][3] = {{10, 20, 5}, {4, 40, 8}, {2, 12, 1}};
    const char* modes[3] = {"forward", "decoupled", "reuse"};
    double sums[3] = {0, 0, 0};
    for (int m = 0; m < 3; ++m)
        for (int p = 0; p < 3; ++p) {
            bench["modes"][modes[m]]["passes"].push_back(
                {{"name", "pass" + std::to_string(p)}, {"gpu_ms", ms[m][p]}});
            sums[m] += ms[m][p];
        }
    PlotImage img = plotBench(bench);
    ASSERT_EQ(img.rgba.size(), size_t(img.width) * img.height * 4);
    uint64_t area[3];
    for (int m = 0; m < 3; ++m) area[m] = pixelsOf(img, kPlotModeColours[m]) - 100; // legend
    for (int m = 1; m < 3; ++m)
        EXPECT_NEAR(double(area[m]) / double(area[0]), sums[m] / sums[0], 0.03) << modes[m];
}

TEST(BenchPlot, BenchWritesThePlot) {
    std::string path = (std::filesystem::temp_directory_path() /
                        ("shadel-bench-plot-" + std::to_string(::getpid()) + ".png"))
                           .string();
    BenchOptions b = smallBench();
    b.plot = path;
    testing::internal::CaptureStdout();
    nlohmann::json result = runBench(sharedGpu(), b);
    std::string printed = testing::internal::GetCapturedStdout();
    ASSERT_TRUE(std::filesystem::exists(path));
    // The figures name the machine they are of: on a software device, the host CPU.
    HostInfo host = hostInfo();
    EXPECT_EQ(result["device"], sharedGpu().device.name);
    EXPECT_EQ(result["host"]["cpu"], host.cpu);
    EXPECT_EQ(result["host"]["threads"], host.threads);
    EXPECT_EQ(result["modes"]["reuse"]["host"]["cpu"], host.cpu); // each mode's render stats
    if (sharedGpu().device.isCpu) {
        EXPECT_NE(printed.find("on " + host.cpu + ", "), std::string::npos) << printed;
    }
    EXPECT_GT(std::filesystem::file_size(path), 1000u);
    PlotImage img = plotBench(result);
    // Every mode has its bar. Bar areas follow the measured times (BarAreasFollowThePassTimes),
    // and one cold frame's times vary by 100x (pipeline compiles, a warm shader cache for one
    // mode and not another), so no fixed area is asserted here.
    for (int m = 0; m < 3; ++m) EXPECT_GT(pixelsOf(img, kPlotModeColours[m]), 0u) << m;
    EXPECT_EQ(validationErrors(), 0u);
    std::filesystem::remove(path);
}

// --rounds N: every round runs the three modes (in opposite order each round); each ratio is
// the median of the rounds' ratios, each over forward's frame of the same round.
TEST(BenchPlot, BenchRoundsReportTheMedianOfTheRoundsRatios) {
    BenchOptions b = smallBench();
    b.modeRounds = 3;
    nlohmann::json result = runBench(sharedGpu(), b);
    EXPECT_EQ(result["rounds"].get<uint32_t>(), 3u);
    std::vector<double> fwd = result["modes"]["forward"]["frame_ms_rounds"];
    ASSERT_EQ(fwd.size(), 3u);
    for (const char* mode : {"decoupled", "reuse"}) {
        std::vector<double> ms = result["modes"][mode]["frame_ms_rounds"];
        std::vector<double> ratios = result["ratios_by_round"][mode];
        ASSERT_EQ(ms.size(), 3u) << mode;
        ASSERT_EQ(ratios.size(), 3u) << mode;
        for (size_t r = 0; r < 3; ++r) {
            ASSERT_GT(fwd[r], 0.0);
            EXPECT_NEAR(ratios[r], ms[r] / fwd[r], 1e-9) << mode << " round " << r;
        }
        std::sort(ratios.begin(), ratios.end());
        EXPECT_NEAR(result["ratios"][mode].get<double>(), ratios[1], 1e-12) << mode;
    }
    EXPECT_EQ(validationErrors(), 0u);
}
