#pragma once
// Size bound of the on-disk cache: least-recently-used files are removed once the folder holds
// more than the limit. Every file the engine caches counts: bakes, texture-streaming files,
// prefiltered environments, mesh distance fields (sdf/) and pipeline caches. "Used" is the file's
// modification time, which every cache read refreshes (access times are unreliable: relatime,
// noatime mounts).
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

enum class CacheKind : uint8_t { Bake, TextureStreaming, Environment, DistanceField, Pipelines };
constexpr int kCacheKindCount = 5;
const char* cacheKindName(CacheKind kind);

// What a cache folder holds, per kind, and the temporary files of writers still running or
// killed mid-write.
struct CacheReport {
    CacheUsage kinds[kCacheKindCount];
    CacheUsage total; // every kind
    CacheUsage temporaries;
};

// A missing folder is an empty cache.
CacheReport cacheUsage(const std::string& dir);

// Marks a cache file as just used (best effort: a read-only cache stays as it is).
void markCacheFileUsed(const std::string& path);

// Removes the least recently used cache files, never those named in `keep` (paths relative to
// `dir`, this run's), until the cache holds at most limitBytes; then the temporary files of
// writers that died. Returns what was removed. limitBytes = 0 means no size limit.
CacheUsage evictCache(const std::string& dir, uint64_t limitBytes,
                      const std::set<std::string>& keep);

// Removes the temporary files of writers that are gone (killed mid-write): their process no
// longer exists and the file is a minute old, or the file is a day old.
CacheUsage removeStaleTemporaries(const std::string& dir);

// Removes every cache file and every temporary file. Returns what was removed.
CacheUsage cleanCache(const std::string& dir);

// Parses "4G", "512M", "100k", "0" (bytes, binary units). Returns false if malformed.
bool parseByteSize(const std::string& text, uint64_t& bytes);

} // namespace shadel
