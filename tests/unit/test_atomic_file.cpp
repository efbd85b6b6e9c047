// Whole-file writes (core/atomic_file.h): a failed write names the file and the reason and
// leaves nothing behind, not even a temporary file, and never a truncated target.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/atomic_file.h"
#include "temp_dir.h"

using namespace shadel;
using shadel::test::TempDir;
namespace fs = std::filesystem;

namespace {

std::string readText(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// A full disk for this process: files may not grow beyond `bytes` (write fails with EFBIG
// instead of raising SIGXFSZ). Restored on destruction.
class FileSizeLimit {
public:
    explicit FileSizeLimit(rlim_t bytes) {
        previousHandler_ = std::signal(SIGXFSZ, SIG_IGN);
        getrlimit(RLIMIT_FSIZE, &previous_);
        rlimit limit = previous_;
        limit.rlim_cur = bytes;
        setrlimit(RLIMIT_FSIZE, &limit);
    }
    ~FileSizeLimit() {
        setrlimit(RLIMIT_FSIZE, &previous_);
        std::signal(SIGXFSZ, previousHandler_);
    }

private:
    rlimit previous_{};
    void (*previousHandler_)(int) = nullptr;
};

} // namespace

TEST(AtomicFile, WritesTheWholeFileAndNothingElse) {
    TempDir dir("shadel_atomic_test");
    std::string path = (dir.path / "out.json").string();
    EXPECT_EQ(writeFileAtomically(path, "first", 5), "");
    EXPECT_EQ(writeFileAtomically(path, "second", 6), "");
    EXPECT_EQ(readText(path), "second");
    EXPECT_EQ(dir.entries(), 1u) << "a temporary file was left behind";
}

TEST(AtomicFile, FullDiskLeavesThePreviousFileAndNoTemporary) {
    TempDir dir("shadel_atomic_test");
    std::string path = (dir.path / "image.png").string();
    ASSERT_EQ(writeFileAtomically(path, "old", 3), "");
    std::string big(256 * 1024, 'x');
    std::string error;
    {
        FileSizeLimit limit(16 * 1024);
        error = writeFileAtomically(path, big.data(), big.size());
    }
    EXPECT_EQ(error, path + ": File too large");
    EXPECT_EQ(readText(path), "old") << "the target must not be truncated";
    EXPECT_EQ(dir.entries(), 1u) << "the temporary file must be removed";
}

TEST(AtomicFile, DeviceTargetsAreWrittenInPlaceWithErrorsReported) {
    EXPECT_EQ(writeFileAtomically("/dev/null", "data", 4), "");
    EXPECT_EQ(writeFileAtomically("/dev/full", "data", 4), "/dev/full: No space left on device");
    EXPECT_TRUE(fs::is_character_file("/dev/full")) << "the device node must survive";
}

TEST(AtomicFile, MissingFolderAndDirectoryTargetsAreOneLineErrors) {
    TempDir dir("shadel_atomic_test");
    std::string missing = (dir.path / "no/such/folder/out.png").string();
    EXPECT_EQ(writeFileAtomically(missing, "x", 1), missing + ": No such file or directory");
    EXPECT_EQ(checkFileCreatable(missing), missing + ": No such file or directory");
    EXPECT_EQ(writeFileAtomically(dir.path.string(), "x", 1),
              dir.path.string() + ": Is a directory");
    EXPECT_EQ(checkFileCreatable(dir.path.string()), dir.path.string() + ": Is a directory");
    EXPECT_EQ(checkFileCreatable((dir.path / "new.png").string()), "");
    EXPECT_EQ(checkFileCreatable("/dev/full"), "");
    EXPECT_EQ(dir.entries(), 0u);
}

// A cache entry is never written through what stands at its path: a symbolic link (here to a
// file that stands for a device or a file of the user's) is replaced, its target left as it was.
TEST(CacheEntry, ASymbolicLinkIsReplacedAndItsTargetLeftAlone) {
    TempDir dir("shadel_cache_entry_test");
    fs::path target = dir.path / "precious.txt", entry = dir.path / "bake-0001.bin";
    { std::ofstream(target) << "precious"; }
    fs::create_symlink(target, entry);
    std::vector<uint8_t> bytes;
    EXPECT_EQ(readCacheEntry(entry.string(), 1 << 20, bytes), "a symbolic link");
    EXPECT_TRUE(bytes.empty());
    EXPECT_EQ(writeCacheEntry(entry.string(), "entry", 5), "");
    EXPECT_EQ(readText(target), "precious");
    EXPECT_FALSE(fs::is_symlink(entry));
    EXPECT_EQ(readCacheEntry(entry.string(), 1 << 20, bytes), "");
    EXPECT_EQ(std::string(bytes.begin(), bytes.end()), "entry");
}

// A FIFO at an entry's path neither blocks the read (no writer ever comes) nor the write.
TEST(CacheEntry, AFifoIsNeitherWaitedOnNorWrittenThrough) {
    TempDir dir("shadel_cache_entry_test");
    fs::path entry = dir.path / "environment-0001.bin";
    ASSERT_EQ(::mkfifo(entry.c_str(), 0644), 0);
    std::vector<uint8_t> bytes;
    EXPECT_EQ(readCacheEntry(entry.string(), 1 << 20, bytes), "not a regular file");
    EXPECT_EQ(writeCacheEntry(entry.string(), "entry", 5), "");
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(entry)));
    EXPECT_EQ(readText(entry), "entry");
}

// An entry larger than its kind can be is not read at all (a sparse 1 GiB file here).
TEST(CacheEntry, AnOversizedEntryIsRefusedBeforeItIsRead) {
    TempDir dir("shadel_cache_entry_test");
    fs::path entry = dir.path / "df-0001.bin";
    { std::ofstream(entry) << "x"; }
    fs::resize_file(entry, uint64_t(1) << 30);
    std::vector<uint8_t> bytes;
    std::string why = readCacheEntry(entry.string(), 1 << 20, bytes);
    EXPECT_NE(why.find("more than the 1048576"), std::string::npos) << why;
    EXPECT_TRUE(bytes.empty());
    EXPECT_EQ(readCacheEntry((dir.path / "absent.bin").string(), 1 << 20, bytes), "missing");
}
