// The cache's size limit (--cache-limit): every kind of cache file counts, least recently used
// files go first, files of the scene being baked never, cache hits count as use, temporary files
// of killed writers are removed; `shadel cache clean` removes cache files and leftovers of
// interrupted writers, nothing else; a cache folder someone else controls is not used.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <sys/stat.h>
#include <unistd.h>

#include "bake/bake.h"
#include "bake/bake_cache.h"
#include "bake/cache_eviction.h"
#include "bake/cache_folder.h"
#include "core/atomic_file.h"
#include "core/log.h"
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

fs::path fileOf(const fs::path& path, size_t bytes, int ageSeconds) {
    fs::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << std::string(bytes, 'x');
    fs::last_write_time(path, fs::file_time_type::clock::now() - std::chrono::seconds(ageSeconds));
    return path;
}

// A process id that is not running (the highest pid the kernel hands out is below this).
constexpr long kDeadPid = 2147483646;

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
    EXPECT_EQ(cacheUsage(dir.path.string()).total.bytes, 4000u);

    CacheUsage removed = evictCache(dir.path.string(), 2500, {kept.filename().string()});
    EXPECT_EQ(removed.files, 2u);
    EXPECT_FALSE(fs::exists(oldest));
    EXPECT_TRUE(fs::exists(kept));
    EXPECT_FALSE(fs::exists(middle));
    EXPECT_TRUE(fs::exists(newest));
    EXPECT_TRUE(fs::exists(dir.path / "notes.txt"));
    EXPECT_EQ(evictCache(dir.path.string(), 0, {}).files, 0u) << "0 = no limit";
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
    CacheUsage removed = cleanCache(dir.path.string());
    EXPECT_EQ(removed.files, 3u);
    EXPECT_EQ(cacheUsage(dir.path.string()).total.files, 0u);
    EXPECT_TRUE(fs::exists(dir.path / "keep.me"));
    EXPECT_EQ(cleanCache((dir.path / "missing").string()).files, 0u);
}

TEST(CacheEviction, EveryKindOfCacheFileCountsAndIsEvicted) {
    TempDir dir("shadel_eviction");
    std::string hex(32, 'a');
    fs::path bake = fileOf(dir.path / ("bake-" + hex + ".bin"), 100, 500);
    fs::path textures = fileOf(dir.path / ("textures-" + hex + ".bin"), 1000, 400);
    fs::path environment = fileOf(dir.path / ("environment-" + hex + ".bin"), 200, 300);
    fs::path field = fileOf(dir.path / "sdf" / (hex + ".sdf"), 300, 200);
    fs::path pipelines = fileOf(dir.path / "pipelines-10005-0000.bin", 400, 100);
    fileOf(dir.path / "notes.bin", 5000, 600);                // not a cache name
    fileOf(dir.path / "sdf" / "deeper" / "x.sdf", 5000, 600); // not where fields live
    fs::create_symlink(textures, dir.path / ("textures-" + std::string(32, 'b') + ".bin"));
    CacheReport report = cacheUsage(dir.path.string());
    EXPECT_EQ(report.total.files, 5u) << "links and foreign files never count";
    EXPECT_EQ(report.total.bytes, 2000u);
    EXPECT_EQ(report.kinds[int(CacheKind::TextureStreaming)].bytes, 1000u);
    EXPECT_EQ(report.kinds[int(CacheKind::DistanceField)].files, 1u);
    EXPECT_EQ(report.kinds[int(CacheKind::Pipelines)].files, 1u);

    // Least recently used first, whatever the kind: the bake, then the texture file.
    CacheUsage removed = evictCache(dir.path.string(), 900, {});
    EXPECT_EQ(removed.files, 2u);
    EXPECT_FALSE(fs::exists(bake));
    EXPECT_FALSE(fs::exists(textures));
    EXPECT_TRUE(fs::exists(environment) && fs::exists(field) && fs::exists(pipelines));
    EXPECT_TRUE(fs::exists(dir.path / "notes.bin"));

    CacheUsage cleaned = cleanCache(dir.path.string());
    EXPECT_EQ(cleaned.files, 3u);
    EXPECT_EQ(cacheUsage(dir.path.string()).total.files, 0u);
    EXPECT_TRUE(fs::exists(dir.path / "sdf" / "deeper" / "x.sdf"));
}

TEST(CacheEviction, TemporariesOfKilledWritersAreRemovedLiveOnesKept) {
    TempDir dir("shadel_eviction");
    std::string name = "textures-" + std::string(32, 'c') + ".bin";
    int writes = 0; // the writer's counter: one process may leave several
    auto temporary = [&](long pid, int ageSeconds, const char* sub = "") {
        return fileOf(dir.path / sub / format(".%s.tmp.%ld.%d", name.c_str(), pid, writes++), 64,
                      ageSeconds);
    };
    fs::path killed = temporary(kDeadPid, 120);
    fs::path killedJustNow = temporary(kDeadPid + 1, 5); // a minute's grace
    fs::path running = temporary(long(::getpid()), 3600);
    fs::path ancient = temporary(long(::getpid()), 2 * 24 * 3600);
    std::string fieldTemporary =
        format(".%s.sdf.tmp.%ld.3", std::string(32, 'd').c_str(), kDeadPid);
    fs::path killedField = fileOf(dir.path / "sdf" / fieldTemporary, 64, 120);
    fs::path foreign = fileOf(dir.path / format(".notes.txt.tmp.%ld.0", kDeadPid), 64, 120);
    EXPECT_EQ(cacheUsage(dir.path.string()).temporaries.files, 5u);

    CacheUsage removed = removeStaleTemporaries(dir.path.string());
    EXPECT_EQ(removed.files, 3u);
    EXPECT_FALSE(fs::exists(killed));
    EXPECT_FALSE(fs::exists(killedField));
    EXPECT_FALSE(fs::exists(ancient)) << "a day-old temporary is stale whatever its pid";
    EXPECT_TRUE(fs::exists(killedJustNow));
    EXPECT_TRUE(fs::exists(running));
    EXPECT_TRUE(fs::exists(foreign)) << "not a cache file's temporary";
}

TEST(CacheFolder, CreatedPrivateAndRefusedWhenSomeoneElseControlsIt) {
    TempDir dir("shadel_cache_folder");
    fs::path fresh = dir.path / "new" / "cache";
    EXPECT_EQ(checkCacheFolder(fresh.string()), "");
    struct stat st {};
    ASSERT_EQ(::stat(fresh.c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0700u) << "a cache folder the engine makes is private";

    fs::path open = dir.path / "world-writable";
    fs::create_directory(open);
    fs::permissions(open, fs::perms::all);
    EXPECT_EQ(checkCacheFolder(open.string()), "writable by every user");
    EXPECT_EQ(usableCacheFolder(open.string()), "") << "no cache rather than a shared one";

    fs::path file = dir.path / "a-file";
    std::ofstream(file) << "x";
    EXPECT_EQ(checkCacheFolder(file.string()), "not a directory");

    if (::geteuid() != 0) GTEST_SKIP() << "changing a folder's owner needs root";
    fs::path planted = dir.path / "planted";
    fs::create_directory(planted);
    ASSERT_EQ(::chown(planted.c_str(), 65534, 65534), 0);
    EXPECT_EQ(checkCacheFolder(planted.string()).rfind("owned by user 65534", 0), 0u)
        << checkCacheFolder(planted.string());
    EXPECT_EQ(usableCacheFolder(planted.string()), "");

    // An entry planted by another user is not read either.
    fs::path entry = dir.path / "new" / "cache" / ("bake-" + std::string(32, 'e') + ".bin");
    std::ofstream(entry) << "planted";
    ASSERT_EQ(::chown(entry.c_str(), 65534, 65534), 0);
    std::vector<uint8_t> bytes;
    EXPECT_EQ(readCacheEntry(entry.string(), 1 << 20, bytes), "owned by user 65534, not this user");
}
