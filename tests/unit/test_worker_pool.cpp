#include <atomic>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "core/worker_pool.h"

using namespace shadel;

TEST(WorkerPool, EveryIndexRunsExactlyOnceAcrossManyRounds) {
    WorkerPool pool(4);
    EXPECT_EQ(pool.threads(), 4u);
    for (uint32_t round = 0; round < 200; ++round) {
        uint32_t count = round % 37; // includes 0 and counts below the thread count
        std::vector<std::atomic<uint32_t>> runs(count);
        pool.parallelFor(count, [&](uint32_t i, uint32_t worker) {
            ASSERT_LT(worker, 4u);
            runs[i].fetch_add(1);
        });
        for (uint32_t i = 0; i < count; ++i) ASSERT_EQ(runs[i].load(), 1u) << "round " << round;
    }
}

TEST(WorkerPool, NoTwoBodiesShareAWorkerAtOnce) {
    WorkerPool pool(3);
    std::vector<std::atomic<int>> active(3);
    std::atomic<bool> overlap{false};
    std::set<uint32_t> workersSeen;
    std::mutex seenMutex;
    pool.parallelFor(64, [&](uint32_t, uint32_t worker) {
        if (active[worker].fetch_add(1) != 0) overlap = true;
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        active[worker].fetch_sub(1);
        std::lock_guard lock(seenMutex);
        workersSeen.insert(worker);
    });
    EXPECT_FALSE(overlap.load());
    EXPECT_GE(workersSeen.size(), 2u); // 64 sleeping bodies are shared out
}

TEST(WorkerPool, OneThreadRunsInOrderOnTheCaller) {
    WorkerPool pool(1);
    std::vector<uint32_t> order;
    std::thread::id caller = std::this_thread::get_id();
    pool.parallelFor(5, [&](uint32_t i, uint32_t worker) {
        EXPECT_EQ(worker, 0u);
        EXPECT_EQ(std::this_thread::get_id(), caller);
        order.push_back(i);
    });
    EXPECT_EQ(order, (std::vector<uint32_t>{0, 1, 2, 3, 4}));
}

TEST(WorkerPool, ABodysExceptionReachesTheCallerAndThePoolStaysUsable) {
    WorkerPool pool(2);
    EXPECT_THROW(pool.parallelFor(16,
                                  [&](uint32_t i, uint32_t) {
                                      if (i == 5) throw std::runtime_error("body 5 failed");
                                  }),
                 std::runtime_error);
    std::atomic<uint32_t> ran{0};
    pool.parallelFor(10, [&](uint32_t, uint32_t) { ran++; });
    EXPECT_EQ(ran.load(), 10u);
}
