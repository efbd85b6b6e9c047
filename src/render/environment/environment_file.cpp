#include "render/environment/environment_file.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>

#include <stb/stb_image.h>
#include <tinyexr.h>

#include "core/error.h"
#include "core/log.h"

namespace shadel {

namespace {

std::string extensionOf(const std::string& path) {
    size_t dot = path.find_last_of('.');
    size_t slash = path.find_last_of('/');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string ext = path.substr(dot + 1);
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

void checkSize(const std::string& path, long long width, long long height) {
    if (width < 8 || height < 4 || width > kEnvironmentMaxWidth || height > kEnvironmentMaxHeight)
        throw InputError(format("%s: environment image is %lldx%lld; it must be from 8x4 to %ux%u",
                                path.c_str(), width, height, kEnvironmentMaxWidth,
                                kEnvironmentMaxHeight));
    double aspect = double(width) / double(height);
    if (aspect < 1.5 || aspect > 2.5)
        throw InputError(format("%s: environment image is %lldx%lld, not an equirectangular "
                                "panorama (width:height must be about 2:1)",
                                path.c_str(), width, height));
}

// Copies `channels`-wide float pixels into the image, zeroing negative and non-finite texels.
EquirectImage fromFloats(const std::string& path, const float* pixels, int width, int height,
                         int channels) {
    EquirectImage image = makeEquirect(uint32_t(width), uint32_t(height));
    size_t bad = 0;
    bool anyLight = false;
    for (size_t i = 0; i < image.texels.size(); ++i) {
        glm::vec3 c(pixels[i * channels], pixels[i * channels + 1], pixels[i * channels + 2]);
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(c[k]) || c[k] < 0.0f) c[k] = 0.0f, ++bad;
        anyLight = anyLight || c.r > 0.0f || c.g > 0.0f || c.b > 0.0f;
        image.texels[i] = c;
    }
    if (bad) SHADEL_WARN("%s: %zu negative or non-finite values read as 0", path.c_str(), bad);
    if (!anyLight) throw InputError(format("%s: environment image holds no light", path.c_str()));
    return image;
}

EquirectImage decodeHdr(const std::string& path, const std::vector<uint8_t>& bytes) {
    auto* data = reinterpret_cast<const stbi_uc*>(bytes.data());
    int size = int(std::min<size_t>(bytes.size(), size_t(INT32_MAX)));
    int w = 0, h = 0, n = 0;
    if (!stbi_is_hdr_from_memory(data, size) || !stbi_info_from_memory(data, size, &w, &h, &n))
        throw InputError(format("%s: not a Radiance HDR file", path.c_str()));
    checkSize(path, w, h);
    float* pixels = stbi_loadf_from_memory(data, size, &w, &h, &n, 3);
    if (!pixels) {
        const char* why = stbi_failure_reason();
        throw InputError(format("%s: cannot decode: %s", path.c_str(), why ? why : "unknown"));
    }
    try {
        EquirectImage image = fromFloats(path, pixels, w, h, 3);
        stbi_image_free(pixels);
        return image;
    } catch (...) {
        stbi_image_free(pixels);
        throw;
    }
}

EquirectImage decodeExr(const std::string& path, const std::vector<uint8_t>& bytes) {
    EXRVersion version;
    if (ParseEXRVersionFromMemory(&version, bytes.data(), bytes.size()) != TINYEXR_SUCCESS)
        throw InputError(format("%s: not an OpenEXR file", path.c_str()));
    if (version.multipart || version.non_image)
        throw InputError(format("%s: multi-part or deep EXR is not supported", path.c_str()));
    EXRHeader header;
    InitEXRHeader(&header);
    const char* err = nullptr;
    if (ParseEXRHeaderFromMemory(&header, &version, bytes.data(), bytes.size(), &err) !=
        TINYEXR_SUCCESS) {
        std::string why = err ? err : "bad header";
        if (err) FreeEXRErrorMessage(err);
        throw InputError(format("%s: cannot read the EXR header: %s", path.c_str(), why.c_str()));
    }
    long long w = (long long)header.data_window.max_x - header.data_window.min_x + 1;
    long long h = (long long)header.data_window.max_y - header.data_window.min_y + 1;
    FreeEXRHeader(&header);
    checkSize(path, w, h);
    float* rgba = nullptr;
    int width = 0, height = 0;
    if (LoadEXRFromMemory(&rgba, &width, &height, bytes.data(), bytes.size(), &err) !=
        TINYEXR_SUCCESS) {
        std::string why = err ? err : "unknown error";
        if (err) FreeEXRErrorMessage(err);
        throw InputError(format("%s: cannot decode: %s", path.c_str(), why.c_str()));
    }
    try {
        checkSize(path, width, height);
        EquirectImage image = fromFloats(path, rgba, width, height, 4);
        std::free(rgba);
        return image;
    } catch (...) {
        std::free(rgba);
        throw;
    }
}

} // namespace

std::vector<uint8_t> readEnvironmentFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(format("%s: cannot open the environment file", path.c_str()));
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                               std::istreambuf_iterator<char>());
    if (in.bad()) throw InputError(format("%s: cannot read the environment file", path.c_str()));
    return bytes;
}

EquirectImage decodeEnvironmentFile(const std::string& path, const std::vector<uint8_t>& bytes) {
    std::string ext = extensionOf(path);
    if (bytes.empty()) throw InputError(format("%s: the environment file is empty", path.c_str()));
    if (ext == "hdr") return decodeHdr(path, bytes);
    if (ext == "exr") return decodeExr(path, bytes);
    throw InputError(format("%s: an environment must be builtin:sky, none, a .hdr or an .exr file",
                            path.c_str()));
}

} // namespace shadel
