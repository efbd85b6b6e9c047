# One ctest test per GoogleTest suite (all of a suite's tests in one process), for the GPU tests.
#
# Why not one process per test (gtest_discover_tests): on lavapipe a renderer spends seconds
# creating its pipelines, and the device's pipeline library shares them only within a process.
# One process per suite lets a suite's tests share them; the suite's output names the failing
# test. Run one test alone with the binary: shadel_gpu_tests --gtest_filter=Suite.Test.
#
# The suites are listed when ctest starts (like gtest_discover_tests' PRE_TEST mode), so a new
# suite is picked up without re-running CMake. COSTS (Suite=seconds, measured on lavapipe) only
# order a run on a fresh build directory heaviest first, so two long suites do not end up
# last; after one run ctest orders by its own measurements.
#
#   shadel_add_gtest_suites(<target> LABEL <label> TIMEOUT <seconds> [COSTS Suite=s ...])
function(shadel_add_gtest_suites target)
  cmake_parse_arguments(ARG "" "LABEL;TIMEOUT" "COSTS" ${ARGN})
  set(SUITES_BINARY "$<TARGET_FILE:${target}>")
  set(SUITES_PREFIX "${target}")
  set(SUITES_LABEL "${ARG_LABEL}")
  set(SUITES_TIMEOUT "${ARG_TIMEOUT}")
  set(SUITES_COSTS "${ARG_COSTS}")
  set(configured "${CMAKE_CURRENT_BINARY_DIR}/${target}_suites.cmake.in")
  set(generated "${CMAKE_CURRENT_BINARY_DIR}/${target}_suites.cmake")
  configure_file("${PROJECT_SOURCE_DIR}/cmake/gtest_suites_ctest.cmake.in" "${configured}" @ONLY)
  file(GENERATE OUTPUT "${generated}" INPUT "${configured}")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${generated}")
endfunction()
