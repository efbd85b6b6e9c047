#pragma once
// Size bound of the on-disk bake cache: least-recently-used files are removed once the folder
// holds more than the limit. "Used" is the file's modification time, which bakeScene refreshes
// on every cache hit (access times are unreliable: relatime, noatime mounts).
#include <cstdint>
#include <set>
#include <string>

namespace shadel {

// The default --cache-limit: a few scenes' worth of ID maps.
constexpr uint64_t kDefaultBakeCacheLimitBytes = 4ull << 30;

struct CacheUsage {
    uint64_t bytes = 0;
    uint64_t files = 0;
};

// Bake-cache files (bake-*.bin) in `dir`; a missing folder is an empty cache.
CacheUsage bakeCacheUsage(const std::string& dir);

// Marks a cache file as just used (best effort: a read-only cache stays as it is).
void markBakeCacheFileUsed(const std::string& path);

// Removes the least recently used cache files, never those named in `keep` (file names, this
// run's), until the cache holds at most limitBytes. Returns what was removed. limitBytes = 0 means
// no limit.
CacheUsage evictBakeCache(const std::string& dir, uint64_t limitBytes,
                          const std::set<std::string>& keep);

// Removes every cache file, and temporary files left by interrupted writers. Returns what was
// removed.
CacheUsage cleanBakeCache(const std::string& dir);

// Parses "4G", "512M", "100k", "0" (bytes, binary units). Returns false if malformed.
bool parseByteSize(const std::string& text, uint64_t& bytes);

} // namespace shadel
