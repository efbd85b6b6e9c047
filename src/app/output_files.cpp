#include "app/output_files.h"

#include <filesystem>

#include <stb/stb_image_write.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"

namespace shadel {

void requireCreatableOutput(const char* flag, const std::string& path) {
    std::string why = checkFileCreatable(path);
    if (!why.empty()) throw InputError(format("%s %s", flag, why.c_str()));
}

void requireDistinctOutputs(const std::vector<std::pair<const char*, std::string>>& outputs) {
    std::vector<std::pair<const char*, std::filesystem::path>> seen;
    for (const auto& [flag, path] : outputs) {
        if (path.empty()) continue;
        std::error_code ec;
        std::filesystem::path file = std::filesystem::weakly_canonical(path, ec);
        if (ec) file = std::filesystem::absolute(path, ec).lexically_normal();
        for (const auto& [otherFlag, other] : seen)
            if (other == file)
                throw InputError(format("%s %s: the same file as %s; give each output its own path",
                                        flag, path.c_str(), otherFlag));
        seen.push_back({flag, file});
    }
}

void writeOutputFile(const std::string& path, const void* data, size_t size) {
    std::string why = writeFileAtomically(path, data, size);
    if (!why.empty()) throw InputError("cannot write " + why);
}

void writeOutputFile(const std::string& path, const std::string& text) {
    writeOutputFile(path, text.data(), text.size());
}

static std::vector<uint8_t> encodePng(const uint8_t* pixels, uint32_t width, uint32_t height,
                                      int channels) {
    std::vector<uint8_t> png;
    auto append = [](void* context, void* data, int size) {
        auto* out = static_cast<std::vector<uint8_t>*>(context);
        const uint8_t* bytes = static_cast<const uint8_t*>(data);
        out->insert(out->end(), bytes, bytes + size);
    };
    if (!stbi_write_png_to_func(append, &png, int(width), int(height), channels, pixels,
                                int(width) * channels))
        throw InputError(format("cannot encode a %ux%u PNG", width, height));
    return png;
}

std::vector<uint8_t> encodePngRgb(const std::vector<uint8_t>& rgba, uint32_t width,
                                  uint32_t height) {
    std::vector<uint8_t> rgb(size_t(width) * height * 3);
    for (size_t i = 0, n = size_t(width) * height; i < n; ++i)
        for (int c = 0; c < 3; ++c) rgb[i * 3 + c] = rgba[i * 4 + c];
    return encodePng(rgb.data(), width, height, 3);
}

std::vector<uint8_t> encodePngRgba(const std::vector<uint8_t>& rgba, uint32_t width,
                                   uint32_t height) {
    return encodePng(rgba.data(), width, height, 4);
}

} // namespace shadel
