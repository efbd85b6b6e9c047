// The 2-D workgroup counts of common/dispatch_2d.h (the shadel queues' indirect dispatches are
// built on the GPU with the same function): every group count n is covered, x stays within the
// 65535 every device allows, rows are as few as x allows and nearly equal, and fewer than y
// groups run past the end (lavapipe gives each thread one contiguous range of the groups: a
// full row beside a nearly empty one put almost all the work on one thread).
#include <vector>

#include <gtest/gtest.h>

#include "common/dispatch_2d.h"

using shadel::shader::dispatch2d;

TEST(Dispatch2d, CoversEveryCountInRowsOfNearlyEqualLength) {
    EXPECT_EQ(dispatch2d(0).x * dispatch2d(0).y, 0u);
    std::vector<uint32_t> counts = {1u,     2u,     63u,     64u,     32768u,  35554u,  65535u,
                                    65536u, 65537u, 131070u, 131071u, 200000u, 1u << 22};
    for (uint32_t n = 1; n < 300000; n += 977) counts.push_back(n);
    for (uint32_t n : counts) {
        auto d = dispatch2d(n);
        SCOPED_TRACE(n);
        ASSERT_GE(uint64_t(d.x) * d.y, n);
        EXPECT_LT(uint64_t(d.x) * d.y - n, d.y) << "fewer than one group per row past the end";
        EXPECT_LE(d.x, 65535u);
        EXPECT_EQ(d.y, (n + 65534u) / 65535u) << "as few rows as x allows";
        if (n <= 65535u) {
            EXPECT_EQ(d.y, 1u);
        }
    }
    // The queue of 35,554 chunks that ran one row on one thread before: now one row.
    EXPECT_EQ(dispatch2d(35554u).x, 35554u);
    EXPECT_EQ(dispatch2d(70000u).x, 35000u);
    EXPECT_EQ(dispatch2d(70000u).y, 2u);
}
