#include "bake/cache_folder.h"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <set>

#include <sys/stat.h>
#include <unistd.h>

#include "core/log.h"

namespace shadel {

std::string defaultCacheFolder() {
    if (const char* dir = std::getenv("SHADEL_CACHE_DIR"); dir && *dir) return dir;
    auto absolute = [](const char* path) { return path && path[0] == '/'; };
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); absolute(xdg))
        return std::string(xdg) + "/shadel";
    if (const char* home = std::getenv("HOME"); absolute(home))
        return std::string(home) + "/.cache/shadel";
    return format("/tmp/shadel-cache-%u", unsigned(::geteuid()));
}

std::string checkCacheFolder(const std::string& dir) {
    if (dir.empty()) return "no folder";
    struct stat st {};
    if (::stat(dir.c_str(), &st) != 0) {
        if (errno != ENOENT) return std::strerror(errno);
        // Parents as the user's umask makes them; the cache folder itself private.
        std::error_code ec;
        std::filesystem::path parent = std::filesystem::path(dir).parent_path();
        if (!parent.empty()) std::filesystem::create_directories(parent, ec);
        if (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST)
            return std::string("cannot create: ") + std::strerror(errno);
        if (::stat(dir.c_str(), &st) != 0) return std::strerror(errno);
    }
    // stat follows a link: a cache folder that is a link to the user's own folder is fine; what
    // counts is the folder the files land in.
    if (!S_ISDIR(st.st_mode)) return "not a directory";
    if (st.st_uid != ::geteuid())
        return format("owned by user %u, not this user (%u)", unsigned(st.st_uid),
                      unsigned(::geteuid()));
    if (st.st_mode & S_IWOTH) return "writable by every user";
    return {};
}

std::string usableCacheFolder(const std::string& requested) {
    std::string dir = requested.empty() ? defaultCacheFolder() : requested;
    std::string why = checkCacheFolder(dir);
    if (why.empty()) return dir;
    static std::mutex mutex;
    static std::set<std::string> warned;
    std::lock_guard lock(mutex);
    if (warned.insert(dir).second)
        SHADEL_WARN("cache folder %s: %s; running without a cache (set --cache-dir or "
                    "SHADEL_CACHE_DIR to a folder of your own)",
                    dir.c_str(), why.c_str());
    return {};
}

} // namespace shadel
