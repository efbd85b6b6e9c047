#include "bake/bake_cache.h"

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <type_traits>

#include <unistd.h>

#include "bake/bake_cache_check.h"
#include "core/atomic_file.h"
#include "core/log.h"

namespace shadel {
namespace {

constexpr char kMagic[8] = {'S', 'H', 'D', 'L', 'B', 'A', 'K', 'E'};
constexpr uint32_t kEndianTag = 0x01020304;

struct FileHeader {
    char magic[8];
    uint32_t version;
    uint32_t endianTag;
    uint64_t keyLo, keyHi;
    uint64_t payloadSize;
    uint64_t payloadChecksum;
};
static_assert(sizeof(FileHeader) == 48);

uint64_t rotl(uint64_t x, int r) {
    return (x << r) | (x >> (64 - r));
}
uint64_t avalanche(uint64_t h) {
    h ^= h >> 33;
    h *= 0xFF51AFD7ED558CCDull;
    h ^= h >> 33;
    h *= 0xC4CEB9FE1A85EC53ull;
    return h ^ (h >> 33);
}

// Streams bytes through two independent hash lanes (different seeds) to form a 128-bit key.
class KeyHasher {
public:
    template <typename T>
    void add(const T& value) {
        static_assert(std::is_trivially_copyable_v<T>);
        addBytes(&value, sizeof value);
    }
    void addBytes(const void* data, size_t size) {
        lo_ = hashBytes(data, size, lo_);
        hi_ = hashBytes(data, size, hi_ ^ 0x5851F42D4C957F2Dull);
    }
    BakeKey key() const { return {lo_, hi_}; }

private:
    uint64_t lo_ = 0x243F6A8885A308D3ull, hi_ = 0x13198A2E03707344ull;
};

class Writer {
public:
    template <typename T>
    void put(const T& value) {
        static_assert(std::is_trivially_copyable_v<T>);
        putBytes(&value, sizeof value);
    }
    template <typename T>
    void putArray(const std::vector<T>& values) {
        put(uint64_t(values.size()));
        putBytes(values.data(), values.size() * sizeof(T));
    }
    void putBytes(const void* data, size_t size) {
        const uint8_t* bytes = static_cast<const uint8_t*>(data);
        buffer.insert(buffer.end(), bytes, bytes + size);
    }
    std::vector<uint8_t> buffer;
};

class Reader {
public:
    Reader(const uint8_t* data, size_t size) : data_(data), size_(size) {}
    template <typename T>
    bool get(T& value) {
        static_assert(std::is_trivially_copyable_v<T>);
        if (size_ - offset_ < sizeof value) return false;
        std::memcpy(&value, data_ + offset_, sizeof value);
        offset_ += sizeof value;
        return true;
    }
    template <typename T>
    bool getArray(std::vector<T>& values, uint64_t expectedCount) {
        uint64_t count = 0;
        if (!get(count) || count != expectedCount) return false;
        if ((size_ - offset_) / sizeof(T) < count) return false;
        values.resize(count);
        std::memcpy(values.data(), data_ + offset_, count * sizeof(T));
        offset_ += count * sizeof(T);
        return true;
    }
    bool atEnd() const { return offset_ == size_; }

private:
    const uint8_t* data_;
    size_t size_;
    size_t offset_ = 0;
};

std::vector<uint8_t> serializePayload(const BakedMesh& b) {
    Writer w;
    w.put(b.width), w.put(b.height), w.put(b.chartCount), w.put(b.triangleCount);
    w.put(b.degenerateTriangles), w.put(b.forcedTriangles), w.put(b.unownedTriangles);
    w.put(uint32_t(b.idMaps.size()));
    w.put(b.utilisation), w.put(b.shadelsPerMetre), w.put(b.surfaceArea);
    w.put(b.meanStretch), w.put(b.maxStretch);
    w.put(uint64_t(b.vertexRemap.size()));
    w.putArray(b.vertexRemap);
    w.putArray(b.shadelUv);
    w.putArray(b.indices);
    for (const std::vector<uint16_t>& level : b.idMaps) w.putArray(level);
    return std::move(w.buffer);
}

// Parses and cross-checks a payload against the mesh it claims to describe.
bool parsePayload(const uint8_t* data, size_t size, const Mesh& mesh, BakedMesh& b,
                  std::string* why) {
    Reader r(data, size);
    uint32_t mipCount = 0;
    uint64_t vertexCount = 0;
    auto fail = [&](const char* reason) {
        *why = reason;
        return false;
    };
    if (!r.get(b.width) || !r.get(b.height) || !r.get(b.chartCount) || !r.get(b.triangleCount) ||
        !r.get(b.degenerateTriangles) || !r.get(b.forcedTriangles) || !r.get(b.unownedTriangles) ||
        !r.get(mipCount) || !r.get(b.utilisation) || !r.get(b.shadelsPerMetre) ||
        !r.get(b.surfaceArea) || !r.get(b.meanStretch) || !r.get(b.maxStretch) ||
        !r.get(vertexCount))
        return fail("truncated header fields");
    if (b.width == 0 || b.height == 0 || b.width % 8 || b.height % 8 || b.width > 65536 ||
        b.height > 65536 || mipCount != bakedMipCount(b.width, b.height))
        return fail("bad resolution");
    if (!(b.meanStretch >= 0.999f && b.maxStretch >= 0.999f * b.meanStretch &&
          std::isfinite(b.maxStretch)))
        return fail("bad stretch");
    if (b.triangleCount != mesh.triangleCount() || vertexCount > mesh.indices.size())
        return fail("does not match the mesh");
    if (!r.getArray(b.vertexRemap, vertexCount) || !r.getArray(b.shadelUv, vertexCount) ||
        !r.getArray(b.indices, mesh.indices.size()))
        return fail("truncated geometry");
    for (uint32_t v : b.vertexRemap)
        if (v >= mesh.vertices.size()) return fail("vertex remap out of range");
    for (glm::vec2 uv : b.shadelUv)
        if (!(uv.x >= 0 && uv.x <= 1 && uv.y >= 0 && uv.y <= 1))
            return fail("shadel UV out of range");
    for (uint32_t i : b.indices)
        if (i >= vertexCount) return fail("index out of range");
    b.idMaps.resize(mipCount);
    for (uint32_t k = 0; k < mipCount; ++k) {
        if (!r.getArray(b.idMaps[k], uint64_t(b.width >> k) * (b.height >> k)))
            return fail("truncated ID map");
        for (uint16_t id : b.idMaps[k])
            if (id != kEmptyShadel && id >= b.triangleCount)
                return fail("triangle ID out of range");
    }
    if (!r.atEnd()) return fail("trailing bytes");
    // The checksum only proves the file is what was written; this proves it fits the mesh.
    if (std::string contradiction = bakeContradictsMesh(mesh, b); !contradiction.empty()) {
        *why = "does not match the mesh: " + contradiction;
        return false;
    }
    return true;
}

// Reads a whole cache entry (core/atomic_file.h): "" or why not ("missing" if it does not
// exist); a link, pipe, device or oversized file where an entry should be is a reason to rebake,
// not to stop (or to wait).
std::string readCacheFile(const std::string& path, std::vector<uint8_t>& bytes) {
    constexpr uint64_t kMaxEntryBytes = uint64_t(4) << 30; // a bake of a mesh at the import limits
    return readCacheEntry(path, kMaxEntryBytes, bytes);
}

} // namespace

uint64_t hashBytes(const void* data, size_t size, uint64_t seed) {
    constexpr uint64_t kP1 = 0x9E3779B185EBCA87ull, kP2 = 0xC2B2AE3D27D4EB4Full;
    const uint8_t* bytes = static_cast<const uint8_t*>(data);
    uint64_t h = seed ^ (uint64_t(size) * kP1);
    size_t i = 0;
    for (; i + 8 <= size; i += 8) {
        uint64_t word;
        std::memcpy(&word, bytes + i, 8);
        h = rotl(h ^ (word * kP2), 31) * kP1;
    }
    uint64_t tail = 0;
    for (size_t k = 0; i + k < size; ++k) tail |= uint64_t(bytes[i + k]) << (8 * k);
    h = rotl(h ^ (tail * kP2), 27) * kP1;
    return avalanche(h);
}

std::string BakeKey::hex() const {
    return format("%016llx%016llx", (unsigned long long)hi, (unsigned long long)lo);
}

BakeKey bakeKey(const Mesh& mesh, const BakeSettings& settings) {
    KeyHasher h;
    h.add(kBakeFormatVersion);
    h.add(settings.shadelsPerMetre), h.add(settings.maxResolution), h.add(settings.minResolution);
    h.add(settings.gutterShadels), h.add(settings.chartConeDegrees);
    h.add(uint64_t(mesh.vertices.size())), h.add(uint64_t(mesh.indices.size()));
    std::vector<float> attributes;
    attributes.reserve(mesh.vertices.size() * 6);
    for (const Vertex& v : mesh.vertices) {
        attributes.insert(attributes.end(), {v.position.x, v.position.y, v.position.z});
        attributes.insert(attributes.end(), {v.normal.x, v.normal.y, v.normal.z});
    }
    h.addBytes(attributes.data(), attributes.size() * sizeof(float));
    h.addBytes(mesh.indices.data(), mesh.indices.size() * sizeof(uint32_t));
    return h.key();
}

std::string bakeCachePath(const std::string& cacheDir, const BakeKey& key) {
    return cacheDir + "/bake-" + key.hex() + ".bin";
}

bool readBakeCache(const std::string& path, const BakeKey& key, const Mesh& mesh, BakedMesh& out,
                   std::string* why) {
    std::string scratch;
    std::string& reason = why ? *why : scratch;
    std::vector<uint8_t> bytes;
    if (std::string error = readCacheFile(path, bytes); !error.empty()) {
        reason = error;
        return false;
    }
    FileHeader header;
    if (bytes.size() < sizeof header) {
        reason = "truncated header";
        return false;
    }
    std::memcpy(&header, bytes.data(), sizeof header);
    if (std::memcmp(header.magic, kMagic, sizeof kMagic) != 0) {
        reason = "bad magic";
        return false;
    }
    if (header.version != kBakeFormatVersion || header.endianTag != kEndianTag) {
        reason = format("stale format version %u (want %u)", header.version, kBakeFormatVersion);
        return false;
    }
    if (header.keyLo != key.lo || header.keyHi != key.hi) {
        reason = "key mismatch";
        return false;
    }
    if (header.payloadSize != bytes.size() - sizeof header) {
        reason = "truncated or oversized payload";
        return false;
    }
    const uint8_t* payload = bytes.data() + sizeof header;
    if (hashBytes(payload, header.payloadSize, 0) != header.payloadChecksum) {
        reason = "checksum mismatch";
        return false;
    }
    BakedMesh parsed;
    if (!parsePayload(payload, header.payloadSize, mesh, parsed, &reason)) return false;
    out = std::move(parsed);
    return true;
}

std::vector<uint8_t> bakeCacheFileBytes(const BakeKey& key, const std::vector<uint8_t>& payload) {
    FileHeader header{};
    std::memcpy(header.magic, kMagic, sizeof kMagic);
    header.version = kBakeFormatVersion;
    header.endianTag = kEndianTag;
    header.keyLo = key.lo, header.keyHi = key.hi;
    header.payloadSize = payload.size();
    header.payloadChecksum = hashBytes(payload.data(), payload.size(), 0);
    std::vector<uint8_t> bytes(sizeof header + payload.size());
    std::memcpy(bytes.data(), &header, sizeof header);
    if (!payload.empty()) std::memcpy(bytes.data() + sizeof header, payload.data(), payload.size());
    return bytes;
}

bool writeBakeCache(const std::string& path, const BakeKey& key, const BakedMesh& baked,
                    std::string* why) {
    namespace fs = std::filesystem;
    std::string scratch;
    std::string& reason = why ? *why : scratch;
    std::vector<uint8_t> bytes = bakeCacheFileBytes(key, serializePayload(baked));
    std::error_code ec;
    fs::path target(path);
    if (target.has_parent_path()) fs::create_directories(target.parent_path(), ec);
    reason = writeCacheEntry(path, bytes.data(), bytes.size());
    return reason.empty();
}

} // namespace shadel
