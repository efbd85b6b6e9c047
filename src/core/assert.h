#pragma once
// CPU asserts that stay on in release builds: a broken invariant in a renderer corrupts
// images silently, so we would rather stop with the location.
#include <cstdio>
#include <cstdlib>

#define SHADEL_ASSERT(cond, ...)                                                                   \
    do {                                                                                           \
        if (!(cond)) [[unlikely]] {                                                                \
            std::fprintf(stderr, "assertion failed: %s (%s:%d)\n", #cond, __FILE__, __LINE__);     \
            std::abort();                                                                          \
        }                                                                                          \
    } while (0)

#define SHADEL_UNREACHABLE() SHADEL_ASSERT(false && "unreachable")
