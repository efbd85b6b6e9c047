#pragma once
// A small fixed pool of worker threads for fork-join work inside a frame (render threading,
// parallel command recording). `parallelFor` hands out indices 0..count-1 to the
// calling thread and the workers as each becomes free, and returns when every index is done.
// The caller is worker 0, so a pool of N threads starts N-1 of its own.
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace shadel {

class WorkerPool {
public:
    explicit WorkerPool(uint32_t threads); // threads >= 1, the caller included
    ~WorkerPool();
    WorkerPool(const WorkerPool&) = delete;
    WorkerPool& operator=(const WorkerPool&) = delete;

    uint32_t threads() const { return uint32_t(workers_.size()) + 1; }

    // Runs body(index, worker) for every index in [0, count); worker is in [0, threads()) and
    // no two bodies with the same worker run at once (per-worker resources need no lock). The
    // first exception thrown by a body is rethrown here after every started body finished.
    void parallelFor(uint32_t count, const std::function<void(uint32_t, uint32_t)>& body);

private:
    void workerLoop(uint32_t worker);
    void runIndices(uint32_t worker);

    std::vector<std::thread> workers_;
    std::mutex mutex_;
    std::condition_variable wake_, done_;
    const std::function<void(uint32_t, uint32_t)>* body_ = nullptr;
    uint32_t count_ = 0, next_ = 0, busy_ = 0;
    uint64_t generation_ = 0;
    bool stopping_ = false;
    std::exception_ptr error_;
};

} // namespace shadel
