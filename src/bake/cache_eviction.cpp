#include "bake/cache_eviction.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <optional>
#include <vector>

#include <signal.h>

#include <fcntl.h>
#include <sys/stat.h>

namespace shadel {
namespace {

namespace fs = std::filesystem;

struct CacheFile {
    fs::path path;
    std::string name; // relative to the cache folder
    CacheKind kind;
    uint64_t bytes = 0;
    fs::file_time_type used;
};

bool startsWith(const std::string& s, const char* prefix) {
    return s.rfind(prefix, 0) == 0;
}
bool endsWith(const std::string& s, const char* suffix) {
    size_t n = std::strlen(suffix);
    return s.size() >= n && s.compare(s.size() - n, n, suffix) == 0;
}

// The kind of a cache file by its name relative to the folder, if it is one (the names the
// writers give: bake_cache.cpp, texture_pack.cpp, environment_cache.cpp, mesh_distance_field.cpp,
// rhi/pipeline_cache.cpp).
std::optional<CacheKind> kindOf(const std::string& name) {
    if (startsWith(name, "sdf/"))
        return endsWith(name, ".sdf") && name.find('/', 4) == std::string::npos
                   ? std::optional(CacheKind::DistanceField)
                   : std::nullopt;
    if (!endsWith(name, ".bin")) return std::nullopt;
    if (startsWith(name, "bake-")) return CacheKind::Bake;
    if (startsWith(name, "textures-")) return CacheKind::TextureStreaming;
    if (startsWith(name, "environment-")) return CacheKind::Environment;
    if (startsWith(name, "pipelines-")) return CacheKind::Pipelines;
    return std::nullopt;
}

// A writer's temporary file: ".<cache file name>.tmp.<pid>.<counter>" beside the target
// (core/atomic_file.cpp). Returns the writer's pid, or 0 if `name` is not one.
long temporaryWriter(const std::string& name) {
    fs::path p(name);
    std::string file = p.filename().string();
    size_t tmp = file.rfind(".tmp.");
    if (file.empty() || file[0] != '.' || tmp == std::string::npos || tmp < 2) return 0;
    std::string target = (p.parent_path() / file.substr(1, tmp - 1)).string();
    if (!kindOf(target)) return 0;
    long pid = std::strtol(file.c_str() + tmp + 5, nullptr, 10);
    return pid > 0 ? pid : 0;
}

// Regular files of the folder and its sdf/ subfolder, as names relative to the folder.
template <typename Visit>
void forEachFile(const std::string& dir, Visit visit) {
    for (const char* sub : {"", "sdf"}) {
        fs::path folder = *sub ? fs::path(dir) / sub : fs::path(dir);
        std::error_code ec;
        for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
            std::error_code fileError;
            // A link or device never counts (and is never removed through).
            if (!it->is_regular_file(fileError) || it->is_symlink(fileError)) continue;
            std::string name = *sub ? std::string(sub) + "/" + it->path().filename().string()
                                    : it->path().filename().string();
            visit(*it, name);
        }
    }
}

std::vector<CacheFile> listCacheFiles(const std::string& dir) {
    std::vector<CacheFile> files;
    forEachFile(dir, [&](const fs::directory_entry& e, const std::string& name) {
        std::optional<CacheKind> kind = kindOf(name);
        if (!kind) return;
        std::error_code ec;
        CacheFile f{e.path(), name, *kind, e.file_size(ec), e.last_write_time(ec)};
        if (!ec) files.push_back(f);
    });
    return files;
}

bool processExists(long pid) {
    return ::kill(pid_t(pid), 0) == 0 || errno != ESRCH;
}

} // namespace

const char* cacheKindName(CacheKind kind) {
    switch (kind) {
    case CacheKind::Bake:
        return "bakes";
    case CacheKind::TextureStreaming:
        return "texture streaming";
    case CacheKind::Environment:
        return "environments";
    case CacheKind::DistanceField:
        return "distance fields";
    case CacheKind::Pipelines:
        return "pipelines";
    }
    return "?";
}

CacheReport cacheUsage(const std::string& dir) {
    CacheReport report;
    for (const CacheFile& f : listCacheFiles(dir)) {
        CacheUsage& k = report.kinds[int(f.kind)];
        k.bytes += f.bytes, ++k.files;
        report.total.bytes += f.bytes, ++report.total.files;
    }
    forEachFile(dir, [&](const fs::directory_entry& e, const std::string& name) {
        std::error_code ec;
        if (temporaryWriter(name))
            report.temporaries.bytes += e.file_size(ec), ++report.temporaries.files;
    });
    return report;
}

void markCacheFileUsed(const std::string& path) {
    ::utimensat(AT_FDCWD, path.c_str(), nullptr, 0);
}

CacheUsage evictCache(const std::string& dir, uint64_t limitBytes,
                      const std::set<std::string>& keep) {
    CacheUsage removed = removeStaleTemporaries(dir);
    if (limitBytes == 0) return removed;
    std::vector<CacheFile> files = listCacheFiles(dir);
    uint64_t total = 0;
    for (const CacheFile& f : files) total += f.bytes;
    if (total <= limitBytes) return removed;
    std::sort(files.begin(), files.end(),
              [](const CacheFile& a, const CacheFile& b) { return a.used < b.used; });
    for (const CacheFile& f : files) {
        if (total <= limitBytes) break;
        if (keep.count(f.name)) continue;
        std::error_code ec;
        // Another process may have removed it first: it is gone either way.
        fs::remove(f.path, ec);
        total -= f.bytes;
        removed.bytes += f.bytes, ++removed.files;
    }
    return removed;
}

CacheUsage removeStaleTemporaries(const std::string& dir) {
    CacheUsage removed;
    const auto now = fs::file_time_type::clock::now();
    forEachFile(dir, [&](const fs::directory_entry& e, const std::string& name) {
        long pid = temporaryWriter(name);
        if (!pid) return;
        std::error_code ec;
        auto age = now - e.last_write_time(ec);
        if (ec) return;
        // A live writer in another PID namespace looks dead here: a minute's grace.
        bool stale =
            age > std::chrono::hours(24) || (age > std::chrono::minutes(1) && !processExists(pid));
        if (!stale) return;
        uint64_t bytes = e.file_size(ec);
        if (fs::remove(e.path(), ec)) removed.bytes += bytes, ++removed.files;
    });
    return removed;
}

CacheUsage cleanCache(const std::string& dir) {
    CacheUsage removed;
    forEachFile(dir, [&](const fs::directory_entry& e, const std::string& name) {
        if (!kindOf(name) && !temporaryWriter(name)) return;
        std::error_code ec;
        uint64_t bytes = e.file_size(ec);
        if (fs::remove(e.path(), ec)) removed.bytes += bytes, ++removed.files;
    });
    return removed;
}

bool parseByteSize(const std::string& text, uint64_t& bytes) {
    size_t digits = 0;
    while (digits < text.size() && std::isdigit(static_cast<unsigned char>(text[digits]))) ++digits;
    if (digits == 0 || digits > 15) return false;
    uint64_t value = std::stoull(text.substr(0, digits));
    std::string unit = text.substr(digits);
    if (!unit.empty() && (unit.back() == 'B' || unit.back() == 'b')) unit.pop_back();
    int shift = 0;
    if (unit == "")
        shift = 0;
    else if (unit == "k" || unit == "K")
        shift = 10;
    else if (unit == "M" || unit == "m")
        shift = 20;
    else if (unit == "G" || unit == "g")
        shift = 30;
    else if (unit == "T" || unit == "t")
        shift = 40;
    else
        return false;
    if (shift > 0 && value > (~0ull >> shift)) return false;
    bytes = value << shift;
    return true;
}

} // namespace shadel
