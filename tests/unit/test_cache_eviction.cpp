// The bake cache's size limit (--cache-limit): least recently used files go first, files of the
// scene being baked never, cache hits count as use; `shadel cache clean` removes cache files and
// leftovers of interrupted writers, nothing else.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "bake/bake.h"
#include "bake/bake_cache.h"
#include "bake/cache_eviction.h"
#include "scene/mesh_utils.h"
#include "temp_dir.h"

using namespace shadel;
using shadel::test::TempDir;
namespace fs = std::filesystem;

namespace {

// A cache-named file of `bytes` bytes last used `ageSeconds` ago.
fs::path cacheFile(const fs::path& dir, char tag, size_t bytes, int ageSeconds) {
    fs::path p = dir / ("bake-" + std::string(32, tag) + ".bin");
    std::ofstream(p, std::ios::binary) << std::string(bytes, 'x');
    fs::last_write_time(p, fs::file_time_type::clock::now() - std::chrono::seconds(ageSeconds));
    return p;
}

} // namespace

TEST(CacheEviction, ByteSizes) {
    uint64_t b = 0;
    EXPECT_TRUE(parseByteSize("0", b));
    EXPECT_EQ(b, 0u);
    EXPECT_TRUE(parseByteSize("4G", b));
    EXPECT_EQ(b, 4ull << 30);
    EXPECT_TRUE(parseByteSize("512MB", b));
    EXPECT_EQ(b, 512ull << 20);
    EXPECT_TRUE(parseByteSize("100k", b));
    EXPECT_EQ(b, 100ull << 10);
    EXPECT_TRUE(parseByteSize("1234", b));
    EXPECT_EQ(b, 1234u);
    for (const char* bad : {"", "G", "-1", "1.5G", "4X", "nan", "99999999999999999T"})
        EXPECT_FALSE(parseByteSize(bad, b)) << bad;
}

TEST(CacheEviction, LeastRecentlyUsedGoFirstKeptFilesNever) {
    TempDir dir("shadel_eviction");
    fs::path oldest = cacheFile(dir.path, 'a', 1000, 400);
    fs::path kept = cacheFile(dir.path, 'b', 1000, 300);
    fs::path middle = cacheFile(dir.path, 'c', 1000, 200);
    fs::path newest = cacheFile(dir.path, 'd', 1000, 100);
    std::ofstream(dir.path / "notes.txt") << std::string(5000, 'n'); // not the cache's
    EXPECT_EQ(bakeCacheUsage(dir.path.string()).bytes, 4000u);

    CacheUsage removed = evictBakeCache(dir.path.string(), 2500, {kept.filename().string()});
    EXPECT_EQ(removed.files, 2u);
    EXPECT_FALSE(fs::exists(oldest));
    EXPECT_TRUE(fs::exists(kept));
    EXPECT_FALSE(fs::exists(middle));
    EXPECT_TRUE(fs::exists(newest));
    EXPECT_TRUE(fs::exists(dir.path / "notes.txt"));
    EXPECT_EQ(evictBakeCache(dir.path.string(), 0, {}).files, 0u) << "0 = no limit";
}

TEST(CacheEviction, BakeSceneTrimsToTheLimitAndHitsCountAsUse) {
    TempDir dir("shadel_eviction");
    std::string cache = dir.path.string();
    Scene first, second;
    first.meshes.push_back(makeBox("first", {1, 2, 3}, 0));
    second.meshes.push_back(makeSphere("second", 0.5f, 0, 24, 12));
    BakeSettings settings;
    fs::path firstFile = bakeCachePath(cache, bakeKey(first.meshes[0], settings));
    fs::path secondFile = bakeCachePath(cache, bakeKey(second.meshes[0], settings));

    bakeScene(first, settings, cache);
    ASSERT_TRUE(fs::exists(firstFile));
    // A hit refreshes the file's use time.
    auto longAgo = fs::file_time_type::clock::now() - std::chrono::hours(24);
    fs::last_write_time(firstFile, longAgo);
    EXPECT_TRUE(bakeScene(first, settings, cache)[0].fromCache);
    EXPECT_GT(fs::last_write_time(firstFile), longAgo + std::chrono::hours(23));

    // A limit below both files: the other scene's file goes, this scene's stays.
    settings.cacheLimitBytes = fs::file_size(firstFile) / 2;
    bakeScene(second, settings, cache);
    EXPECT_FALSE(fs::exists(firstFile));
    EXPECT_TRUE(fs::exists(secondFile));
}

TEST(CacheEviction, CleanRemovesCacheAndLeftoverTemporariesOnly) {
    TempDir dir("shadel_eviction");
    cacheFile(dir.path, 'a', 10, 0);
    cacheFile(dir.path, 'b', 10, 0);
    std::ofstream(dir.path / (".bake-" + std::string(32, 'c') + ".bin.tmp.123.0")) << "partial";
    std::ofstream(dir.path / "keep.me") << "user file";
    CacheUsage removed = cleanBakeCache(dir.path.string());
    EXPECT_EQ(removed.files, 3u);
    EXPECT_EQ(bakeCacheUsage(dir.path.string()).files, 0u);
    EXPECT_TRUE(fs::exists(dir.path / "keep.me"));
    EXPECT_EQ(cleanBakeCache((dir.path / "missing").string()).files, 0u);
}
