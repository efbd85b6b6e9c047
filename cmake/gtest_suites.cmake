# One ctest test per GoogleTest suite (all of a suite's tests in one process), for the GPU tests.
#
# Why not one process per test (gtest_discover_tests): on lavapipe a renderer spends seconds
# creating its pipelines, and the device's pipeline library shares them only within a process.
# One process per suite lets a suite's tests share them; the suite's output names the failing
# test. Run one test alone with the binary: GTEST_FILTER=Suite.Test shadel_gpu_tests.
#
# The suites are listed when ctest starts (like gtest_discover_tests' PRE_TEST mode), so a new
# suite is picked up without re-running CMake. A listing that fails or finds no suite becomes a
# failing test. COSTS (Suite=seconds, measured on lavapipe) order every run heaviest first, so
# two long suites do not end up last (ctest's own measurements only order tests without a COST);
# a stale figure changes only the order. SKIP_RETURN_CODE: the exit code of a suite whose every
# test skipped (the test binary's main returns it).
#
#   shadel_add_gtest_suites(<target> LABEL <label> TIMEOUT <seconds>
#                           [SKIP_RETURN_CODE <code>] [COSTS Suite=seconds ...])
function(shadel_add_gtest_suites target)
  cmake_parse_arguments(ARG "" "LABEL;TIMEOUT;SKIP_RETURN_CODE" "COSTS" ${ARGN})
  set(SUITES_BINARY "$<TARGET_FILE:${target}>")
  set(SUITES_PREFIX "${target}")
  set(SUITES_LABEL "${ARG_LABEL}")
  set(SUITES_TIMEOUT "${ARG_TIMEOUT}")
  set(SUITES_SKIP_RETURN_CODE "${ARG_SKIP_RETURN_CODE}")
  set(SUITES_COSTS "${ARG_COSTS}")
  set(configured "${CMAKE_CURRENT_BINARY_DIR}/${target}_suites.cmake.in")
  configure_file("${PROJECT_SOURCE_DIR}/cmake/gtest_suites_ctest.cmake.in" "${configured}" @ONLY)
  get_property(multi_config GLOBAL PROPERTY GENERATOR_IS_MULTI_CONFIG)
  if(multi_config)
    # One script per configuration (the binary's path differs), chosen by ctest -C.
    set(per_config "${CMAKE_CURRENT_BINARY_DIR}/${target}_suites-$<CONFIG>.cmake")
    file(GENERATE OUTPUT "${per_config}" INPUT "${configured}")
    set(generated "${CMAKE_CURRENT_BINARY_DIR}/${target}_suites.cmake")
    file(WRITE "${generated}"
         "if(NOT CTEST_CONFIGURATION_TYPE)\n"
         "  message(WARNING \"${target}: its suites need ctest -C <config>\")\n"
         "else()\n"
         "  include(\"${CMAKE_CURRENT_BINARY_DIR}/${target}_suites-\${CTEST_CONFIGURATION_TYPE}.cmake\")\n"
         "endif()\n")
  else()
    set(generated "${CMAKE_CURRENT_BINARY_DIR}/${target}_suites.cmake")
    file(GENERATE OUTPUT "${generated}" INPUT "${configured}")
  endif()
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${generated}")
endfunction()
