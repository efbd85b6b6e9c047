#pragma once
// One memory budget for loading a scene file: every large allocation a load makes (the file,
// external buffers and images, decoded pixels, meshopt fallback buffers, accessor reads, mesh
// vertices, skins, instances) is charged before it is made. A small hostile file that would
// expand into gigabytes (twenty images naming one 8192² PNG, buffers naming one sparse 1 GiB
// file, a million-joint skin) stops at the limit with one line naming the input and what
// exceeded it, instead of exhausting the machine.
#include <cstdint>
#include <string>

namespace shadel {

// The process-wide limit (--load-memory-limit): a quarter of physical memory, at most 2 GiB
// (a scene that needs more says so and the flag raises it).
uint64_t defaultLoadMemoryLimit();
void setLoadMemoryLimit(uint64_t bytes); // 0: the default
uint64_t loadMemoryLimit();

// The budget of the load running on this thread (loads are single-threaded; playback imports
// the next frame on a worker, with its own budget).
class LoadBudgetScope {
public:
    explicit LoadBudgetScope(std::string input, uint64_t limitBytes = loadMemoryLimit());
    ~LoadBudgetScope();
    LoadBudgetScope(const LoadBudgetScope&) = delete;
    LoadBudgetScope& operator=(const LoadBudgetScope&) = delete;
    uint64_t used() const { return used_; }

private:
    friend void chargeLoadMemory(uint64_t bytes, const char* what);
    std::string input_;
    uint64_t limit_ = 0, used_ = 0;
    LoadBudgetScope* outer_ = nullptr;
};

// Charges `bytes` to this thread's load budget (nothing when no load is running). Throws
// InputError "<input>: <what> needs N MiB more, over the M MiB load memory limit
// (--load-memory-limit)".
void chargeLoadMemory(uint64_t bytes, const char* what);

} // namespace shadel
