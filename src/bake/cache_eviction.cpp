#include "bake/cache_eviction.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>

namespace shadel {
namespace {

namespace fs = std::filesystem;

struct CacheFile {
    fs::path path;
    uint64_t bytes = 0;
    fs::file_time_type used;
};

bool isCacheFile(const std::string& name) {
    return name.rfind("bake-", 0) == 0 && name.size() > 9 &&
           name.compare(name.size() - 4, 4, ".bin") == 0;
}

// Left by a writer that died between creating and renaming (core/atomic_file.cpp naming).
bool isTemporaryFile(const std::string& name) {
    return name.rfind(".bake-", 0) == 0 && name.find(".bin.tmp.") != std::string::npos;
}

std::vector<CacheFile> listCacheFiles(const std::string& dir) {
    std::vector<CacheFile> files;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        if (!isCacheFile(it->path().filename().string())) continue;
        std::error_code fileError;
        if (!it->is_regular_file(fileError)) continue;
        CacheFile f{it->path(), it->file_size(fileError), it->last_write_time(fileError)};
        if (!fileError) files.push_back(f);
    }
    return files;
}

} // namespace

CacheUsage bakeCacheUsage(const std::string& dir) {
    CacheUsage usage;
    for (const CacheFile& f : listCacheFiles(dir)) usage.bytes += f.bytes, ++usage.files;
    return usage;
}

void markBakeCacheFileUsed(const std::string& path) {
    ::utimensat(AT_FDCWD, path.c_str(), nullptr, 0);
}

CacheUsage evictBakeCache(const std::string& dir, uint64_t limitBytes,
                          const std::set<std::string>& keep) {
    CacheUsage removed;
    if (limitBytes == 0) return removed;
    std::vector<CacheFile> files = listCacheFiles(dir);
    uint64_t total = 0;
    for (const CacheFile& f : files) total += f.bytes;
    if (total <= limitBytes) return removed;
    std::sort(files.begin(), files.end(),
              [](const CacheFile& a, const CacheFile& b) { return a.used < b.used; });
    for (const CacheFile& f : files) {
        if (total <= limitBytes) break;
        if (keep.count(f.path.filename().string())) continue;
        std::error_code ec;
        // Another process may have removed it first: it is gone either way.
        fs::remove(f.path, ec);
        total -= f.bytes;
        removed.bytes += f.bytes, ++removed.files;
    }
    return removed;
}

CacheUsage cleanBakeCache(const std::string& dir) {
    CacheUsage removed;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        std::string name = it->path().filename().string();
        if (!isCacheFile(name) && !isTemporaryFile(name)) continue;
        std::error_code fileError;
        if (!it->is_regular_file(fileError)) continue;
        uint64_t bytes = it->file_size(fileError);
        if (fs::remove(it->path(), fileError)) removed.bytes += bytes, ++removed.files;
    }
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
