#include "core/atomic_file.h"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/log.h"

namespace shadel {
namespace {

std::string failure(const std::string& path, int error) {
    return path + ": " + std::strerror(error);
}

// write() until done; returns 0 or the errno of the first failure.
int writeAll(int fd, const void* data, size_t size) {
    const char* bytes = static_cast<const char*>(data);
    while (size > 0) {
        ssize_t n = ::write(fd, bytes, size);
        if (n < 0) {
            if (errno == EINTR) continue;
            return errno;
        }
        bytes += n;
        size -= size_t(n);
    }
    return 0;
}

// Why an existing non-regular path cannot be an output, or "": writing a FIFO or socket waits for
// a reader (forever, for a FIFO nobody reads), and writing a block device overwrites a disk.
// Character devices (/dev/null, /dev/stdout, /dev/full) never wait and stay usable.
std::string unwritableKind(const struct stat& st) {
    if (S_ISFIFO(st.st_mode)) return "a FIFO, not a file";
    if (S_ISSOCK(st.st_mode)) return "a socket, not a file";
    if (S_ISBLK(st.st_mode)) return "a block device, not a file";
    return {};
}

std::string folderOf(const std::string& path) {
    std::string folder = std::filesystem::path(path).parent_path().string();
    return folder.empty() ? "." : folder;
}

// Writes in place (devices, pipes): there is nothing to rename, but errors still count.
std::string writeInPlace(const std::string& path, const void* data, size_t size) {
    int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) return failure(path, errno);
    int error = writeAll(fd, data, size);
    // fsync on a device or pipe may legitimately be unsupported (EINVAL); only close's verdict
    // and the writes' count.
    if (::close(fd) != 0 && error == 0) error = errno;
    return error ? failure(path, error) : std::string();
}

} // namespace

// Writes a temporary file next to path and renames it over path.
static std::string writeViaTemporary(const std::string& path, const void* data, size_t size) {
    static std::atomic<unsigned long long> counter{0};
    // Hidden, unique per process and call, in the target's folder (same file system).
    std::filesystem::path target(path);
    std::string name =
        format(".%s.tmp.%d.%llu", target.filename().c_str(), int(::getpid()), counter.fetch_add(1));
    std::string temp = (target.parent_path() / name).string();
    int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) return failure(path, errno);
    int error = writeAll(fd, data, size);
    // Delayed allocation: on some file systems a full disk only shows at fsync or close.
    if (error == 0 && ::fsync(fd) != 0 && errno != EINVAL) error = errno;
    if (::close(fd) != 0 && error == 0) error = errno;
    if (error == 0 && ::rename(temp.c_str(), path.c_str()) != 0) error = errno;
    if (error != 0) {
        ::unlink(temp.c_str());
        return failure(path, error);
    }
    return {};
}

std::string writeFileAtomically(const std::string& path, const void* data, size_t size) {
    struct stat existing {};
    if (::stat(path.c_str(), &existing) == 0) {
        if (S_ISDIR(existing.st_mode)) return failure(path, EISDIR);
        if (std::string kind = unwritableKind(existing); !kind.empty()) return path + ": " + kind;
        if (!S_ISREG(existing.st_mode)) return writeInPlace(path, data, size);
    }
    return writeViaTemporary(path, data, size);
}

std::string writeCacheEntry(const std::string& path, const void* data, size_t size) {
    // lstat: a symbolic link is judged as itself, never by what it points to.
    struct stat existing {};
    if (::lstat(path.c_str(), &existing) == 0 && S_ISDIR(existing.st_mode))
        return failure(path, EISDIR);
    return writeViaTemporary(path, data, size);
}

std::string readCacheEntry(const std::string& path, uint64_t maxBytes,
                           std::vector<uint8_t>& bytes) {
    bytes.clear();
    // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer forever.
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
    if (fd < 0) {
        if (errno == ENOENT) return "missing";
        if (errno == ELOOP) return "a symbolic link";
        return std::string("cannot open: ") + std::strerror(errno);
    }
    struct stat st {};
    std::string why;
    if (::fstat(fd, &st) != 0)
        why = std::string("cannot stat: ") + std::strerror(errno);
    else if (!S_ISREG(st.st_mode))
        why = "not a regular file";
    else if (st.st_uid != ::geteuid())
        why = format("owned by user %u, not this user", unsigned(st.st_uid));
    else if (uint64_t(st.st_size) > maxBytes)
        why = format("%llu bytes, more than the %llu an entry may hold",
                     (unsigned long long)st.st_size, (unsigned long long)maxBytes);
    if (why.empty()) {
        bytes.resize(size_t(st.st_size));
        size_t done = 0;
        while (done < bytes.size()) {
            ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                why = n == 0 ? "shorter than its size"
                             : std::string("read error: ") + std::strerror(errno);
                break;
            }
            done += size_t(n);
        }
    }
    // A read is a use: least-recently-used eviction goes by modification time (access times are
    // unreliable under relatime and noatime). Best effort: a read-only cache stays as it is.
    if (why.empty()) ::futimens(fd, nullptr);
    ::close(fd);
    if (!why.empty()) bytes.clear();
    return why;
}

std::string checkFileCreatable(const std::string& path) {
    if (path.empty()) return "output path is empty";
    struct stat existing {};
    if (::stat(path.c_str(), &existing) == 0) {
        if (S_ISDIR(existing.st_mode)) return failure(path, EISDIR);
        if (std::string kind = unwritableKind(existing); !kind.empty()) return path + ": " + kind;
        if (!S_ISREG(existing.st_mode))
            return ::access(path.c_str(), W_OK) == 0 ? std::string() : failure(path, errno);
    }
    std::string folder = folderOf(path);
    struct stat dir {};
    if (::stat(folder.c_str(), &dir) != 0) return failure(path, errno);
    if (!S_ISDIR(dir.st_mode)) return failure(path, ENOTDIR);
    if (::access(folder.c_str(), W_OK) != 0) return failure(path, errno);
    return {};
}

} // namespace shadel
