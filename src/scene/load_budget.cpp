#include "scene/load_budget.h"

#include <algorithm>
#include <atomic>

#include <unistd.h>

#include "core/error.h"
#include "core/log.h"

namespace shadel {
namespace {

std::atomic<uint64_t> configuredLimit{0};
thread_local LoadBudgetScope* current = nullptr;

double mib(uint64_t bytes) {
    return double(bytes) / (1 << 20);
}

} // namespace

uint64_t defaultLoadMemoryLimit() {
    long pages = ::sysconf(_SC_PHYS_PAGES), pageSize = ::sysconf(_SC_PAGE_SIZE);
    uint64_t physical = pages > 0 && pageSize > 0 ? uint64_t(pages) * uint64_t(pageSize) : 0;
    const uint64_t cap = 2ull << 30;
    return physical ? std::min(physical / 4, cap) : cap;
}

void setLoadMemoryLimit(uint64_t bytes) {
    configuredLimit = bytes;
}

uint64_t loadMemoryLimit() {
    uint64_t limit = configuredLimit;
    return limit ? limit : defaultLoadMemoryLimit();
}

LoadBudgetScope::LoadBudgetScope(std::string input, uint64_t limitBytes)
    : input_(std::move(input)), limit_(limitBytes), outer_(current) {
    current = this;
}

LoadBudgetScope::~LoadBudgetScope() {
    current = outer_;
}

void chargeLoadMemory(uint64_t bytes, const char* what) {
    LoadBudgetScope* budget = current;
    if (!budget) return;
    if (bytes > budget->limit_ - std::min(budget->used_, budget->limit_))
        throw InputError(format("%s: %s needs %.1f MiB more after %.1f MiB, over the %.0f MiB "
                                "load memory limit (--load-memory-limit)",
                                budget->input_.c_str(), what, mib(bytes), mib(budget->used_),
                                mib(budget->limit_)));
    budget->used_ += bytes;
}

} // namespace shadel
