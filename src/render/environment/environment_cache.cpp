#include "render/environment/environment_cache.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/atomic_file.h"
#include "core/log.h"

namespace shadel {

namespace {

constexpr char kMagic[8] = {'S', 'H', 'D', 'L', 'E', 'N', 'V', 'M'};
constexpr uint32_t kEndianTag = 0x01020304u;
constexpr uint32_t kMaxImages = 64;

struct Header {
    char magic[8];
    uint32_t version;
    uint32_t endian;
    uint64_t keyLo, keyHi;
    uint64_t payloadSize;
    uint64_t checksum;
};

template <typename T>
bool take(const std::vector<uint8_t>& bytes, size_t& offset, T& out) {
    if (bytes.size() - offset < sizeof(T)) return false;
    std::memcpy(&out, bytes.data() + offset, sizeof(T));
    offset += sizeof(T);
    return true;
}

bool parsePayload(const std::vector<uint8_t>& bytes, size_t offset,
                  std::vector<EquirectImage>& images, std::string* why) {
    uint32_t count = 0;
    if (!take(bytes, offset, count) || count == 0 || count > kMaxImages)
        return *why = "bad image count", false;
    images.clear();
    for (uint32_t i = 0; i < count; ++i) {
        uint32_t w = 0, h = 0;
        if (!take(bytes, offset, w) || !take(bytes, offset, h) || w == 0 || h == 0 || w > 16384 ||
            h > 16384)
            return *why = format("bad size of image %u", i), false;
        size_t floats = size_t(w) * h * 3;
        if ((bytes.size() - offset) / sizeof(float) < floats)
            return *why = format("image %u is truncated", i), false;
        EquirectImage image = makeEquirect(w, h);
        std::memcpy(image.texels.data(), bytes.data() + offset, floats * sizeof(float));
        offset += floats * sizeof(float);
        for (const glm::vec3& t : image.texels)
            for (int c = 0; c < 3; ++c)
                if (!std::isfinite(t[c]) || t[c] < 0.0f)
                    return *why = format("image %u holds a bad value", i), false;
        images.push_back(std::move(image));
    }
    if (offset != bytes.size()) return *why = "trailing bytes", false;
    return true;
}

} // namespace

std::string environmentCachePath(const std::string& cacheDir, const BakeKey& key) {
    return cacheDir + "/environment-" + key.hex() + ".bin";
}

bool readEnvironmentCache(const std::string& path, const BakeKey& key,
                          std::vector<EquirectImage>& images, std::string* why) {
    std::string ignored;
    if (!why) why = &ignored;
    // The largest maps: a 2048x1024 background and the levels, as RGB floats, well under this.
    constexpr uint64_t kMaxEntryBytes = uint64_t(256) << 20;
    std::vector<uint8_t> bytes;
    if (std::string reason = readCacheEntry(path, kMaxEntryBytes, bytes); !reason.empty())
        return *why = reason, false;
    Header h{};
    size_t offset = 0;
    if (!take(bytes, offset, h)) return *why = "truncated header", false;
    if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) return *why = "not a cache file", false;
    if (h.version != kEnvironmentFormatVersion) return *why = "older format", false;
    if (h.endian != kEndianTag) return *why = "other endianness", false;
    if (h.keyLo != key.lo || h.keyHi != key.hi) return *why = "other key", false;
    if (h.payloadSize != bytes.size() - offset) return *why = "truncated or padded", false;
    if (hashBytes(bytes.data() + offset, bytes.size() - offset, 0) != h.checksum)
        return *why = "checksum mismatch", false;
    return parsePayload(bytes, offset, images, why);
}

bool writeEnvironmentCache(const std::string& path, const BakeKey& key,
                           const std::vector<EquirectImage>& images, std::string* why) {
    std::vector<uint8_t> payload;
    auto put = [&](const void* data, size_t size) {
        const uint8_t* p = static_cast<const uint8_t*>(data);
        payload.insert(payload.end(), p, p + size);
    };
    uint32_t count = uint32_t(images.size());
    put(&count, sizeof count);
    for (const EquirectImage& image : images) {
        put(&image.width, sizeof image.width);
        put(&image.height, sizeof image.height);
        put(image.texels.data(), image.texels.size() * sizeof(glm::vec3));
    }
    Header h{};
    std::memcpy(h.magic, kMagic, sizeof kMagic);
    h.version = kEnvironmentFormatVersion;
    h.endian = kEndianTag;
    h.keyLo = key.lo, h.keyHi = key.hi;
    h.payloadSize = payload.size();
    h.checksum = hashBytes(payload.data(), payload.size(), 0);
    std::vector<uint8_t> bytes(sizeof h);
    std::memcpy(bytes.data(), &h, sizeof h);
    bytes.insert(bytes.end(), payload.begin(), payload.end());
    std::error_code ec;
    std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ec);
    std::string error = writeCacheEntry(path, bytes.data(), bytes.size());
    if (!error.empty()) {
        if (why) *why = error;
        return false;
    }
    return true;
}

} // namespace shadel
