// --trace FILE.json: Chrome trace events, one GPU event per pass per frame, named as --passes
// names them, plus the CPU frontend of each frame.
#include "gpu_test_env.h"

#include <filesystem>
#include <fstream>
#include <map>

using namespace shadel;
using namespace shadel::test;

TEST(Trace, OneEventPerPassPerFrameNamedAsThePasses) {
    std::string path = (std::filesystem::temp_directory_path() /
                        ("shadel-trace-" + std::to_string(::getpid()) + ".json"))
                           .string();
    RenderOptions o;
    o.scene = "builtin:smooth";
    o.mode = RenderMode::Decoupled;
    o.width = 96;
    o.height = 54;
    o.frames = 3;
    o.trace = path;
    RenderRun run = renderChecked(o);
    nlohmann::json trace = takeJsonFile(path);
    ASSERT_FALSE(trace.is_null()) << path;

    std::map<std::string, int> gpuEvents;
    int frames = 0, frontends = 0;
    double lastStart = -1.0;
    for (const auto& e : trace["traceEvents"]) {
        if (e["ph"] != "X") continue;
        EXPECT_GE(e["dur"].get<double>(), 0.0);
        if (e["cat"] == "gpu") gpuEvents[e["name"].get<std::string>()]++;
        if (e["cat"] == "cpu" && e["name"].get<std::string>().rfind("frame ", 0) == 0) {
            ++frames;
            EXPECT_GT(e["ts"].get<double>(), lastStart); // frames in order
            lastStart = e["ts"].get<double>();
        }
        if (e["name"] == "frontend") ++frontends;
    }
    EXPECT_EQ(frames, 3);
    EXPECT_EQ(frontends, 3);
    ASSERT_FALSE(run.stats["passes"].empty());
    EXPECT_EQ(gpuEvents.size(), run.stats["passes"].size());
    for (const auto& p : run.stats["passes"])
        EXPECT_EQ(gpuEvents[p["name"].get<std::string>()], 3) << p["name"];
    EXPECT_GT(run.stats["cpu_frame_ms"].get<double>(), 0.0);
}
