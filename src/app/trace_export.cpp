#include "app/trace_export.h"

namespace shadel {

nlohmann::json chromeTrace(const std::vector<FrameResult>& frames, const std::string& label) {
    constexpr int kPid = 1, kCpuTrack = 1, kGpuTrack = 2;
    nlohmann::json events = nlohmann::json::array();
    auto meta = [&](const char* what, int tid, const std::string& name) {
        nlohmann::json e = {{"name", what}, {"ph", "M"}, {"pid", kPid}, {"args", {{"name", name}}}};
        if (tid) e["tid"] = tid;
        events.push_back(e);
    };
    meta("process_name", 0, "shadel " + label);
    meta("thread_name", kCpuTrack, "CPU");
    meta("thread_name", kGpuTrack, "GPU passes");
    auto span = [&](const std::string& name, const char* category, int tid, double startMs,
                    double durationMs, nlohmann::json args) {
        events.push_back({{"name", name},
                          {"cat", category},
                          {"ph", "X"},
                          {"pid", kPid},
                          {"tid", tid},
                          {"ts", startMs * 1000.0},
                          {"dur", durationMs * 1000.0},
                          {"args", std::move(args)}});
    };
    for (size_t i = 0; i < frames.size(); ++i) {
        const FrameResult& f = frames[i];
        span("frame " + std::to_string(i), "cpu", kCpuTrack, f.startMs, f.frameMs,
             {{"frame", i}, {"cpu_frame_ms", f.cpuFrameMs}});
        span("frontend", "cpu", kCpuTrack, f.startMs, f.cpuPrepareMs, {{"frame", i}});
        // GPU passes start after the frontend has prepared the frame.
        double gpuStart = f.startMs + f.cpuPrepareMs;
        for (const PassTiming& p : f.passes)
            span(p.name, "gpu", kGpuTrack, gpuStart + p.startMs, p.gpuMs, {{"frame", i}});
    }
    return {{"traceEvents", events}, {"displayTimeUnit", "ms"}};
}

} // namespace shadel
