#include "app/cache_command.h"

#include <cstdint>
#include <cstdio>

#include "bake/cache_eviction.h"
#include "bake/cache_folder.h"

namespace shadel {

static double mib(uint64_t bytes) {
    return double(bytes) / (1 << 20);
}

int runCacheCommand(const std::string& dir, bool clean, uint64_t limitBytes) {
    std::string trust = checkCacheFolder(dir);
    if (!trust.empty()) {
        std::fprintf(stderr, "error: cache folder %s: %s; not used by this user's runs\n",
                     dir.c_str(), trust.c_str());
        return 2;
    }
    if (clean) {
        CacheUsage removed = cleanCache(dir);
        std::printf("removed %llu files (%.1f MiB) from %s\n", (unsigned long long)removed.files,
                    mib(removed.bytes), dir.c_str());
    }
    CacheReport report = cacheUsage(dir);
    std::printf("cache: %s\n%llu files, %.1f MiB (limit %s)\n", dir.c_str(),
                (unsigned long long)report.total.files, mib(report.total.bytes),
                limitBytes ? (std::to_string(limitBytes >> 20) + " MiB").c_str() : "none");
    for (int k = 0; k < kCacheKindCount; ++k)
        std::printf("  %-18s %6llu files %10.1f MiB\n", cacheKindName(CacheKind(k)),
                    (unsigned long long)report.kinds[k].files, mib(report.kinds[k].bytes));
    if (report.temporaries.files)
        std::printf("  %-18s %6llu files %10.1f MiB (writers running, or killed mid-write)\n",
                    "temporary", (unsigned long long)report.temporaries.files,
                    mib(report.temporaries.bytes));
    return 0;
}

} // namespace shadel
