// --trace FILE.json: Chrome trace events, one GPU event per pass per frame, named as --passes
// names them, plus the CPU frontend of each frame.
#include "gpu_test_env.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

using namespace shadel;
using namespace shadel::test;

namespace {

// builtin:smooth in decoupled mode, 96x54, 3 frames, with --trace: the run and its trace.
struct TracedRun {
    RenderRun run;
    nlohmann::json trace;
};
TracedRun tracedRun(const std::string& name) {
    std::string path = tempPath(name + ".json");
    RenderOptions o = renderOptions("builtin:smooth", RenderMode::Decoupled, 96, 54);
    o.frames = 3;
    o.trace = path;
    TracedRun t{renderChecked(o), nlohmann::json()};
    t.trace = takeJsonFile(path);
    return t;
}

} // namespace

TEST(Trace, OneEventPerPassPerFrameNamedAsThePasses) {
    auto [run, trace] = tracedRun("trace");
    ASSERT_FALSE(trace.is_null());

    std::map<std::string, int> gpuEvents;
    int frames = 0, frontends = 0;
    double lastStart = -1.0;
    std::map<int, double> frameStart, frameDuration, gpuDuration; // per frame, microseconds
    for (const auto& e : trace["traceEvents"]) {
        if (e["ph"] != "X") continue;
        // Every span measured something (steady clocks with nanosecond steps).
        EXPECT_GT(e["dur"].get<double>(), 0.0) << e["name"];
        int frame = e["args"].value("frame", -1);
        if (e["cat"] == "gpu") {
            gpuEvents[e["name"].get<std::string>()]++;
            gpuDuration[frame] += e["dur"].get<double>();
            EXPECT_GT(e["ts"].get<double>(), frameStart.at(frame)) << e["name"]; // frame first
        }
        if (e["cat"] == "cpu" && e["name"].get<std::string>().rfind("frame ", 0) == 0) {
            ++frames;
            EXPECT_GT(e["ts"].get<double>(), lastStart); // frames in order
            lastStart = e["ts"].get<double>();
            frameStart[frame] = e["ts"].get<double>();
            frameDuration[frame] = e["dur"].get<double>();
        }
        if (e["name"] == "frontend") ++frontends;
    }
    EXPECT_EQ(frames, 3);
    EXPECT_EQ(frontends, 3);
    // A frame's passes run one after another inside it: their times sum to no more than the
    // frame's (from its start to the GPU finishing).
    for (auto& [frame, gpuUs] : gpuDuration)
        EXPECT_LE(gpuUs, frameDuration.at(frame))
            << "frame " << frame << ": passes " << gpuUs << " us, frame " << frameDuration[frame];
    ASSERT_FALSE(run.stats["passes"].empty());
    EXPECT_EQ(gpuEvents.size(), run.stats["passes"].size());
    // One event for each frame a pass ran: every frame, but the kept sun shadow map
    // (render/lighting/sun_shadow_cache.h) is drawn on the first frame only.
    for (const auto& p : run.stats["passes"]) {
        std::string name = p["name"];
        EXPECT_EQ(gpuEvents[name], p["frames"].get<int>()) << name;
        EXPECT_EQ(p["frames"].get<int>(), name == "shadowMap" ? 1 : 3) << name;
    }
    EXPECT_GT(run.stats["cpu_frame_ms"].get<double>(), 0.0);
}

// --trace itemises the render thread's CPU (the frontend's steps, every submit) with its thread
// CPU time beside the wall clock, and the stats list the same scopes (median per frame).
TEST(Trace, CpuScopesItemiseTheFrontendAndEverySubmit) {
    auto [run, trace] = tracedRun("trace-scopes");
    ASSERT_FALSE(trace.is_null());

    struct Span {
        double start, end;
    };
    std::map<int, Span> frontend;
    std::map<int, std::vector<Span>> allocation;
    std::map<int, std::map<std::string, int>> submits; // per frame, per pass
    std::map<int, std::map<std::string, int>> passes;
    for (const auto& e : trace["traceEvents"]) {
        if (e["ph"] != "X") continue;
        int frame = e["args"]["frame"].get<int>();
        std::string name = e["name"].get<std::string>();
        double ts = e["ts"].get<double>(), dur = e["dur"].get<double>();
        if (e["cat"] == "gpu") passes[frame][name]++;
        if (e["cat"] != "cpu") continue;
        if (name == "frontend") frontend[frame] = {ts, ts + dur};
        if (name == "decoupled coarse allocation" || name.rfind("submit ", 0) == 0) {
            ASSERT_TRUE(e["args"].contains("thread_cpu_ms")) << name;
            double cpuMs = e["args"]["thread_cpu_ms"].get<double>();
            EXPECT_GT(cpuMs, 0.0) << name; // a thread CPU clock with nanosecond steps
            // A thread cannot run longer than the wall clock (+ the clocks' granularity).
            EXPECT_LE(cpuMs, dur / 1000.0 + 0.05) << name;
        }
        if (name == "decoupled coarse allocation") allocation[frame].push_back({ts, ts + dur});
        if (name.rfind("submit ", 0) == 0) submits[frame][name.substr(7)]++;
    }
    ASSERT_EQ(frontend.size(), 3u);
    for (int f = 0; f < 3; ++f) {
        ASSERT_EQ(allocation[f].size(), 1u) << "frame " << f;
        // Inside its frame's frontend (microseconds; the export rounds nothing).
        EXPECT_GE(allocation[f][0].start, frontend[f].start - 1e-3) << "frame " << f;
        EXPECT_LE(allocation[f][0].end, frontend[f].end + 1e-3) << "frame " << f;
        // Submit per pass on lavapipe (timestamps elsewhere: one submit for the frame).
        if (run.stats["timing"] == "submit-per-pass")
            EXPECT_EQ(submits[f], passes[f]) << "frame " << f;
        else
            EXPECT_EQ(submits[f], (std::map<std::string, int>{{"frame", 1}})) << "frame " << f;
    }
    std::map<std::string, double> statScopes;
    for (const auto& s : run.stats["cpu_scopes"])
        statScopes[s["name"].get<std::string>()] = s["thread_cpu_ms"].get<double>();
    EXPECT_TRUE(statScopes.count("decoupled coarse allocation"));
    EXPECT_TRUE(statScopes.count("submit (all passes)"));
    for (const auto& p : run.stats["passes"]) EXPECT_TRUE(p.contains("record_cpu_ms")) << p["name"];
}

// Every slice lies within its parent on its track (what Perfetto needs to nest them): on each
// (pid, tid), slices in start order form a stack, and one that starts inside an open slice
// ends inside it too. Checked over 8 frames of the default scene, where the end-frame scope
// once ended up to 0.3 ms after its frame. The GPU passes are a process of their own ("GPU").
TEST(Trace, EverySliceLiesWithinItsParentOnItsTrack) {
    std::string path = tempPath("trace-nesting.json");
    RenderOptions o = renderOptions("builtin:default", RenderMode::Decoupled, 160, 90);
    o.frames = 8;
    o.trace = path;
    RenderRun run = renderChecked(o);
    nlohmann::json trace = takeJsonFile(path);
    ASSERT_FALSE(trace.is_null()) << path;

    struct Slice {
        std::string name;
        double start, end; // microseconds
    };
    std::map<std::pair<int, int>, std::vector<Slice>> tracks;
    std::map<int, std::string> processNames;
    std::set<int> gpuPids;
    int frames = 0;
    for (const auto& e : trace["traceEvents"]) {
        if (e["ph"] == "M" && e["name"] == "process_name")
            processNames[e["pid"].get<int>()] = e["args"]["name"].get<std::string>();
        if (e["ph"] != "X") continue;
        double ts = e["ts"].get<double>(), dur = e["dur"].get<double>();
        tracks[{e["pid"].get<int>(), e["tid"].get<int>()}].push_back(
            {e["name"].get<std::string>(), ts, ts + dur});
        if (e["cat"] == "gpu") gpuPids.insert(e["pid"].get<int>());
        frames += e["name"].get<std::string>().rfind("frame ", 0) == 0;
    }
    EXPECT_EQ(frames, 8);
    ASSERT_EQ(gpuPids.size(), 1u);
    EXPECT_EQ(processNames[*gpuPids.begin()], "GPU");
    for (const auto& e : trace["traceEvents"]) { // nothing else shares the GPU's process
        if (e["ph"] == "X" && e["pid"] == *gpuPids.begin()) {
            EXPECT_EQ(e["cat"], "gpu") << e["name"];
        }
    }

    constexpr double kEpsUs = 1e-3; // a nanosecond: the export's doubles, not a tolerance
    size_t nested = 0;
    for (auto& [track, slices] : tracks) {
        std::stable_sort(slices.begin(), slices.end(), [](const Slice& a, const Slice& b) {
            return a.start != b.start ? a.start < b.start : a.end > b.end;
        });
        std::vector<const Slice*> open;
        for (const Slice& s : slices) {
            while (!open.empty() && open.back()->end <= s.start + kEpsUs) open.pop_back();
            if (!open.empty()) {
                ++nested;
                EXPECT_LE(s.end, open.back()->end + kEpsUs)
                    << "track " << track.first << "/" << track.second << ": \"" << s.name
                    << "\" ends " << s.end - open.back()->end << " us after its parent \""
                    << open.back()->name << "\"";
            }
            open.push_back(&s);
        }
    }
    EXPECT_GT(nested, 8u * 3u); // frontend, its steps and the submits nest in every frame
}
