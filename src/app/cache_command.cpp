#include "app/cache_command.h"

#include <cstdint>
#include <cstdio>

#include "bake/cache_eviction.h"

namespace shadel {

int runCacheCommand(const std::string& dir, bool clean, uint64_t limitBytes) {
    if (clean) {
        CacheUsage removed = cleanBakeCache(dir);
        std::printf("removed %llu files (%.1f MiB) from %s\n", (unsigned long long)removed.files,
                    double(removed.bytes) / (1 << 20), dir.c_str());
    }
    CacheUsage usage = bakeCacheUsage(dir);
    std::printf("bake cache: %s\n%llu files, %.1f MiB (limit %s)\n", dir.c_str(),
                (unsigned long long)usage.files, double(usage.bytes) / (1 << 20),
                limitBytes ? (std::to_string(limitBytes >> 20) + " MiB").c_str() : "none");
    return 0;
}

} // namespace shadel
