#include "core/cpu_scope.h"

#include <ctime>

namespace shadel {

double threadCpuMs() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

CpuScopeTimer::CpuScopeTimer(std::vector<CpuScope>* out, const char* name, Clock::time_point origin)
    : out_(out), name_(name), origin_(origin) {
    if (!out_) return;
    start_ = Clock::now();
    cpuStart_ = threadCpuMs();
}

void CpuScopeTimer::stop() {
    if (!out_) return;
    double cpu = threadCpuMs() - cpuStart_;
    Clock::time_point end = Clock::now();
    auto ms = [](Clock::duration d) {
        return std::chrono::duration<double, std::milli>(d).count();
    };
    out_->push_back({name_, ms(start_ - origin_), ms(end - start_), cpu});
    out_ = nullptr;
}

} // namespace shadel
