#include "core/worker_pool.h"

#include "core/assert.h"

namespace shadel {

WorkerPool::WorkerPool(uint32_t threads) {
    SHADEL_ASSERT(threads >= 1);
    for (uint32_t w = 1; w < threads; ++w) workers_.emplace_back([this, w] { workerLoop(w); });
}

WorkerPool::~WorkerPool() {
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : workers_) t.join();
}

// Takes indices until none is left; the lock is held only to take one.
void WorkerPool::runIndices(uint32_t worker) {
    std::unique_lock lock(mutex_);
    while (next_ < count_) {
        uint32_t index = next_++;
        ++busy_;
        lock.unlock();
        try {
            (*body_)(index, worker);
        } catch (...) {
            lock.lock();
            if (!error_) error_ = std::current_exception();
            next_ = count_; // start nothing more
            --busy_;
            continue;
        }
        lock.lock();
        --busy_;
    }
    if (busy_ == 0) done_.notify_all();
}

void WorkerPool::workerLoop(uint32_t worker) {
    uint64_t seen = 0;
    for (;;) {
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [&] { return stopping_ || generation_ != seen; });
            if (stopping_) return;
            seen = generation_;
        }
        runIndices(worker);
    }
}

void WorkerPool::parallelFor(uint32_t count, const std::function<void(uint32_t, uint32_t)>& body) {
    if (count == 0) return;
    {
        std::lock_guard lock(mutex_);
        SHADEL_ASSERT(body_ == nullptr); // not reentrant
        body_ = &body;
        count_ = count;
        next_ = 0;
        busy_ = 0;
        error_ = nullptr;
        ++generation_;
    }
    wake_.notify_all();
    runIndices(0);
    std::exception_ptr error;
    {
        std::unique_lock lock(mutex_);
        done_.wait(lock, [&] { return next_ >= count_ && busy_ == 0; });
        body_ = nullptr;
        count_ = 0;
        next_ = 0;
        error = error_;
        error_ = nullptr;
    }
    if (error) std::rethrow_exception(error);
}

} // namespace shadel
