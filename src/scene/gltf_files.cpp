#include "scene/gltf_files.h"

#include <cstring>
#include <filesystem>
#include <fstream>

#include <stb/stb_image.h>

#include "core/error.h"
#include "core/log.h"
#include "scene/load_budget.h"

namespace shadel::gltf {

namespace {

constexpr uint64_t kMaxImagePixels = 1ull << 26;

constexpr uint32_t kGlbChunkJson = 0x4E4F534A;

} // namespace

[[noreturn]] void fail(const std::string& input, const std::string& reason) {
    throw InputError(input + ": " + reason);
}

std::string oneLine(std::string text) {
    for (size_t at = text.find("data:"); at != std::string::npos; at = text.find("data:", at + 1)) {
        size_t end = text.find_first_of(" \n\"'", at);
        if (end == std::string::npos) end = text.size();
        if (end - at > 48) text.replace(at, end - at, "<data URI>");
    }
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' '))
        text.pop_back();
    for (char& c : text)
        if (c == '\n' || c == '\r') c = ';';
    return text;
}

std::vector<uint8_t> readWholeFile(const std::string& path, const std::string& input) {
    std::error_code ec;
    auto status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status)) fail(input, "file not found");
    if (!std::filesystem::is_regular_file(status)) fail(input, "not a regular file");
    uint64_t size = std::filesystem::file_size(path, ec);
    if (ec) fail(input, "cannot read file size");
    if (size > kMaxFileBytes)
        fail(input, format("file is %llu bytes, more than the %llu-byte limit",
                           (unsigned long long)size, (unsigned long long)kMaxFileBytes));
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(input, "cannot open file");
    std::vector<uint8_t> bytes(size);
    if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size)))
        fail(input, "read error");
    return bytes;
}

uint32_t readU32(const uint8_t* p) {
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}

std::string_view jsonTextOf(const std::vector<uint8_t>& bytes, bool binary,
                            const std::string& input) {
    if (!binary) return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
    if (bytes.size() < 20) fail(input, "truncated GLB header");
    uint32_t version = readU32(&bytes[4]), length = readU32(&bytes[8]);
    uint32_t chunkLength = readU32(&bytes[12]), chunkType = readU32(&bytes[16]);
    if (version != 2)
        fail(input, format("binary glTF version %u is not supported (need 2)", version));
    if (length > bytes.size())
        fail(input, format("GLB header says %u bytes but the file has %zu (truncated)", length,
                           bytes.size()));
    if (chunkType != kGlbChunkJson) fail(input, "first GLB chunk is not JSON");
    if (uint64_t(chunkLength) + 20 > length) fail(input, "GLB JSON chunk exceeds the file");
    return {reinterpret_cast<const char*>(bytes.data()) + 20, chunkLength};
}

std::vector<uint8_t> withJsonText(const std::vector<uint8_t>& bytes, bool binary,
                                  std::string text) {
    if (!binary) return std::vector<uint8_t>(text.begin(), text.end());
    while (text.size() % 4 != 0) text.push_back(' ');
    uint32_t oldChunk = readU32(&bytes[12]);
    size_t rest = 20 + size_t(oldChunk); // checked by jsonTextOf
    std::vector<uint8_t> out(20);
    std::memcpy(out.data(), bytes.data(), 12);
    uint32_t chunk = uint32_t(text.size()), type = kGlbChunkJson;
    std::memcpy(&out[12], &chunk, 4);
    std::memcpy(&out[16], &type, 4);
    out.insert(out.end(), text.begin(), text.end());
    if (rest < bytes.size()) out.insert(out.end(), bytes.begin() + long(rest), bytes.end());
    uint32_t length = uint32_t(out.size());
    std::memcpy(&out[8], &length, 4);
    return out;
}

bool decodeImageToRgba8(tinygltf::Image* image, const int index, std::string*, std::string* warn,
                        int, int, const unsigned char* bytes, int size, void*) {
    auto reject = [&](const std::string& why) {
        if (warn) *warn += format("image %d could not be decoded (%s)\n", index, why.c_str());
        image->image.clear();
        image->width = image->height = 0;
        return true;
    };
    int w = 0, h = 0, channels = 0;
    if (!stbi_info_from_memory(bytes, size, &w, &h, &channels))
        return reject(stbi_failure_reason() ? stbi_failure_reason() : "unknown format");
    if (w <= 0 || h <= 0 || uint64_t(w) * uint64_t(h) > kMaxImagePixels)
        return reject(format("%dx%d is too large", w, h));
    // The decoded pixels, and the scene's copy of them (gltf_convert.cpp).
    chargeLoadMemory(uint64_t(w) * uint64_t(h) * 4 * 2, "decoding an image");
    stbi_uc* pixels = stbi_load_from_memory(bytes, size, &w, &h, &channels, 4);
    if (!pixels) return reject(stbi_failure_reason() ? stbi_failure_reason() : "decode failed");
    image->width = w;
    image->height = h;
    image->component = 4;
    image->bits = 8;
    image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    image->image.assign(pixels, pixels + size_t(w) * size_t(h) * 4);
    stbi_image_free(pixels);
    return true;
}

bool fsFileExists(const std::string& path, void* access) {
    if (!static_cast<const FileAccess*>(access)->permits(path)) return false;
    std::error_code ec;
    return std::filesystem::is_regular_file(path, ec);
}
std::string fsExpandPath(const std::string& path, void*) {
    return path;
}
bool fsReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                     void* access) {
    if (!static_cast<const FileAccess*>(access)->permits(path)) {
        if (err) *err += path + " is outside the model's folder";
        return false;
    }
    std::error_code ec;
    uint64_t size = std::filesystem::file_size(path, ec);
    if (ec || size > kMaxFileBytes) {
        if (err) *err += ec ? "cannot read " + path : path + " is larger than the size limit";
        return false;
    }
    chargeLoadMemory(size, "reading a buffer or image file");
    std::ifstream in(path, std::ios::binary);
    out->resize(size);
    if (!in ||
        (size > 0 && !in.read(reinterpret_cast<char*>(out->data()), std::streamsize(size)))) {
        if (err) *err += "cannot read " + path;
        return false;
    }
    return true;
}
bool fsWriteWholeFile(std::string*, const std::string&, const std::vector<unsigned char>&, void*) {
    return false;
}

} // namespace shadel::gltf
