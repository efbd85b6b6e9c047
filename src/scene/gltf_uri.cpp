#include "scene/gltf_uri.h"

#include <filesystem>

namespace shadel {
namespace {

int hexDigit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

} // namespace

std::string decodeUriPath(const std::string& uri) {
    std::string out;
    out.reserve(uri.size());
    for (size_t i = 0; i < uri.size(); ++i) {
        int hi = -1, lo = -1;
        if (uri[i] == '%' && i + 2 < uri.size()) {
            hi = hexDigit(uri[i + 1]);
            lo = hexDigit(uri[i + 2]);
        }
        if (hi >= 0 && lo >= 0) {
            out += char(hi * 16 + lo);
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

bool uriEscapesFolder(const std::string& uri) {
    // Backslashes are separators on Windows, where such a file would be read from elsewhere.
    std::string path = uri;
    for (char& c : path)
        if (c == '\\') c = '/';
    if (!path.empty() && path[0] == '/') return true;
    if (path.size() >= 2 && path[1] == ':') return true; // "C:..." drive letter
    int depth = 0;
    for (const auto& part : std::filesystem::path(path)) {
        std::string name = part.string();
        if (name == "..") {
            if (--depth < 0) return true;
        } else if (!name.empty() && name != "." && name != "/") {
            ++depth;
        }
    }
    return false;
}

bool pathInsideFolder(const std::string& path, const std::string& folder) {
    namespace fs = std::filesystem;
    fs::path base = fs::absolute(fs::path(folder.empty() ? "." : folder)).lexically_normal();
    if (!base.has_filename()) base = base.parent_path(); // "dir/" compares as "dir"
    fs::path target = fs::absolute(fs::path(path)).lexically_normal();
    fs::path relative = target.lexically_relative(base);
    if (relative.empty() || *relative.begin() == "..") return false;
    // And by real path: a link inside the folder to a file outside it is outside.
    std::error_code ec;
    fs::path realBase = fs::weakly_canonical(base, ec);
    if (ec) return false;
    fs::path realTarget = fs::weakly_canonical(target, ec);
    if (ec) return false;
    fs::path realRelative = realTarget.lexically_relative(realBase);
    return !realRelative.empty() && *realRelative.begin() != "..";
}

} // namespace shadel
