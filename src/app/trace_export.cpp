#include "app/trace_export.h"

#include <algorithm>
#include <string>

namespace shadel {

namespace {

// Where a frame's slice on the CPU track ends: frameMs (from beginFrame to the GPU finishing) or
// later, when a CPU scope of the frame ends after it (the end-frame scope also reads the timings
// back after the wait). Every child is measured on the same wall clock from the frame's start,
// so the frame grows to hold them rather than clipping a measured scope: a trace viewer needs
// each slice inside its parent, and the frame did last until its last scope ended.
double frameEndMs(const FrameResult& f) {
    double end = f.startMs + std::max(f.frameMs, f.cpuPrepareMs);
    for (const CpuScope& c : f.cpuScopes) end = std::max(end, f.startMs + c.startMs + c.wallMs);
    return end;
}

} // namespace

nlohmann::json chromeTrace(const std::vector<FrameResult>& frames, const std::string& label) {
    // The CPU threads in one process; the GPU's passes in a process of their own, so a viewer
    // shows them as a separate timeline rather than as one more thread.
    constexpr int kPid = 1, kGpuPid = 2;
    constexpr int kCpuTrack = 1, kGpuTrack = 1, kFrontendTrack = 3, kFirstWorkerTrack = 4;
    nlohmann::json events = nlohmann::json::array();
    auto metaOf = [&](int pid, const char* what, int tid, const std::string& name) {
        nlohmann::json e = {{"name", what}, {"ph", "M"}, {"pid", pid}, {"args", {{"name", name}}}};
        if (tid) e["tid"] = tid;
        events.push_back(e);
    };
    auto meta = [&](const char* what, int tid, const std::string& name) {
        metaOf(kPid, what, tid, name);
    };
    meta("process_name", 0, "shadel " + label);
    meta("thread_name", kCpuTrack, "CPU");
    metaOf(kGpuPid, "process_name", 0, "GPU");
    metaOf(kGpuPid, "thread_name", kGpuTrack, "GPU passes");
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
                          {"pid", std::string(category) == "gpu" ? kGpuPid : kPid},
                          {"tid", tid},
                          {"ts", startMs * 1000.0},
                          {"dur", durationMs * 1000.0},
                          {"args", std::move(args)}});
    };
    for (size_t i = 0; i < frames.size(); ++i) {
        const FrameResult& f = frames[i];
        span("frame " + std::to_string(i), "cpu", kCpuTrack, f.startMs, frameEndMs(f) - f.startMs,
             {{"frame", i}, {"frame_ms", f.frameMs}, {"cpu_frame_ms", f.cpuFrameMs}});
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
