// The GPU tests' main. CTest runs them one process per suite (cmake/gtest_suites.cmake), so a
// suite whose every test skipped (no ray query on the device, no xvfb) exits with
// kAllSkippedExitCode, which CTest reports as skipped (SKIP_RETURN_CODE) rather than passed. A
// suite where only some tests skipped passes; its output lists the skipped ones. Under CI
// (the environment variable CI set) a skipped test fails the run: SHADEL_REQUIRE turns a missing
// capability into a failure there, and this catches any other GTEST_SKIP.
#include <cstdio>

#include <gtest/gtest.h>

#include "gpu_test_env.h"

namespace {
constexpr int kAllSkippedExitCode = 77; // tests/CMakeLists.txt sets SKIP_RETURN_CODE to it
} // namespace

int main(int argc, char** argv) {
    testing::InitGoogleTest(&argc, argv);
    int result = RUN_ALL_TESTS();
    const testing::UnitTest& run = *testing::UnitTest::GetInstance();
    if (result == 0 && run.skipped_test_count() > 0 && shadel::test::runningInCi()) {
        std::fprintf(stderr,
                     "shadel_gpu_tests: %d test(s) skipped and CI is set: CI runs every test\n",
                     run.skipped_test_count());
        return 1;
    }
    if (result == 0 && run.successful_test_count() == 0 && run.skipped_test_count() > 0)
        return kAllSkippedExitCode;
    return result;
}
