#pragma once
// Named CPU scopes of a frame (the trace's finer CPU spans, stats "cpu_scopes"): the wall clock
// and the thread's own CPU time of a stretch of work. On a shared or loaded machine the wall
// clock includes time other processes took the core; the thread CPU time does not, so the two
// side by side tell our work from preemption, and from blocking inside a driver call.
#include <chrono>
#include <string>
#include <vector>

namespace shadel {

// This thread's CPU time in milliseconds (CLOCK_THREAD_CPUTIME_ID).
double threadCpuMs();

struct CpuScope {
    std::string name;
    double startMs = 0.0; // from the owner's origin (a frame's start, a recorder's frame start)
    double wallMs = 0.0;
    double cpuMs = 0.0; // this thread's CPU time inside the scope
};

// Times its own lifetime into `out` (nothing when `out` is null).
class CpuScopeTimer {
public:
    using Clock = std::chrono::steady_clock;
    CpuScopeTimer(std::vector<CpuScope>* out, const char* name, Clock::time_point origin);
    ~CpuScopeTimer() { stop(); }
    void stop(); // ends the scope early (once)
    CpuScopeTimer(const CpuScopeTimer&) = delete;
    CpuScopeTimer& operator=(const CpuScopeTimer&) = delete;

private:
    std::vector<CpuScope>* out_;
    const char* name_;
    Clock::time_point origin_, start_;
    double cpuStart_;
};

} // namespace shadel
