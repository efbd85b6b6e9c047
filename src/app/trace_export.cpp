#include "app/trace_export.h"

#include <algorithm>
#include <string>

namespace shadel {

nlohmann::json chromeTrace(const std::vector<FrameResult>& frames, const std::string& label) {
    constexpr int kPid = 1, kCpuTrack = 1, kGpuTrack = 2, kFrontendTrack = 3, kFirstWorkerTrack = 4;
    nlohmann::json events = nlohmann::json::array();
    auto meta = [&](const char* what, int tid, const std::string& name) {
        nlohmann::json e = {{"name", what}, {"ph", "M"}, {"pid", kPid}, {"args", {{"name", name}}}};
        if (tid) e["tid"] = tid;
        events.push_back(e);
    };
    meta("process_name", 0, "shadel " + label);
    meta("thread_name", kCpuTrack, "CPU");
    meta("thread_name", kGpuTrack, "GPU passes");
    bool frontendWorker = std::any_of(frames.begin(), frames.end(), [](const FrameResult& f) {
        return !f.frontendWorker.empty();
    });
    if (frontendWorker) meta("thread_name", kFrontendTrack, "CPU frontend worker (next frame)");
    size_t workers = 0; // threaded frames: one track per recording worker
    for (const FrameResult& f : frames) workers = std::max(workers, f.recordingWorkers.size());
    for (size_t w = 0; w < workers; ++w)
        meta("thread_name", kFirstWorkerTrack + int(w),
             "CPU recording worker " + std::to_string(w) + (w == 0 ? " (render thread)" : ""));
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
        // Finer scopes of the render thread (--trace): the frontend's steps, the submits.
        for (const CpuScope& c : f.cpuScopes)
            span(c.name, "cpu", kCpuTrack, f.startMs + c.startMs, c.wallMs,
                 {{"frame", i}, {"thread_cpu_ms", c.cpuMs}});
        // GPU passes and recording start after the frontend has prepared the frame.
        double gpuStart = f.startMs + f.cpuPrepareMs;
        for (size_t w = 0; w < f.recordingWorkers.size(); ++w) {
            const RecordingWorkerTiming& t = f.recordingWorkers[w];
            if (!t.passes) continue;
            span("record passes", "cpu", kFirstWorkerTrack + int(w), gpuStart + t.startMs,
                 t.durationMs, {{"frame", i}, {"passes", t.passes}, {"cpu_ms", t.cpuMs}});
        }
        // The next frame's frontend work that ran beside this frame's backend (scene update,
        // coarse visit).
        for (const FrontendWorkerTask& t : f.frontendWorker)
            span(std::string(t.name) + " (frame " + std::to_string(i + 1) + ")", "cpu",
                 kFrontendTrack, t.startMs, t.wallMs, {{"frame", i + 1}, {"cpu_ms", t.cpuMs}});
        for (const PassTiming& p : f.passes)
            span(p.name, "gpu", kGpuTrack, gpuStart + p.startMs, p.gpuMs,
                 {{"frame", i}, {"record_cpu_ms", p.recordCpuMs}});
    }
    return {{"traceEvents", events}, {"displayTimeUnit", "ms"}};
}

} // namespace shadel
