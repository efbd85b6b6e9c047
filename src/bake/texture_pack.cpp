#include "bake/texture_pack.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <thread>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "core/log.h"
#include "core/worker_pool.h"
#include "scene/procedural_textures.h"

namespace shadel {
namespace {

constexpr char kMagic[8] = {'S', 'H', 'D', 'L', 'T', 'E', 'X', 'S'};
constexpr uint32_t kEndianTag = 0x01020304;

struct FileHeader {
    char magic[8];
    uint32_t version;
    uint32_t endianTag;
    uint64_t keyLo, keyHi;
    uint32_t tileSize;
    uint32_t textureCount;
    uint64_t directoryBytes;
    uint64_t directoryChecksum;
    uint64_t fileSize;
};
static_assert(sizeof(FileHeader) == 64);

struct TextureRecord {
    uint32_t size, levels, srgb, format;
    float psnr;
    uint32_t pad;
};
static_assert(sizeof(TextureRecord) == 24);
struct LevelRecord {
    uint64_t offset, bytes, checksum;
};

uint32_t levelCount(uint32_t size) {
    uint32_t n = 1;
    while ((size >> (n - 1)) > 1) ++n;
    return n;
}

uint64_t directoryBytes(const std::vector<uint32_t>& sizes) {
    uint64_t bytes = 0;
    for (uint32_t s : sizes) bytes += sizeof(TextureRecord) + levelCount(s) * sizeof(LevelRecord);
    return bytes;
}

// sRGB <-> linear through tables: mips are averaged in linear light, as the GPU's sRGB sampling
// filters (so a level is what the level above looks like from further away).
struct SrgbTables {
    std::array<float, 256> toLinear;
    std::array<uint8_t, 4096> toSrgb;
    SrgbTables() {
        for (int i = 0; i < 256; ++i) {
            float c = float(i) / 255.0f;
            toLinear[i] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
        }
        for (int i = 0; i < 4096; ++i) {
            float l = (float(i) + 0.5f) / 4096.0f;
            float c = l <= 0.0031308f ? l * 12.92f : 1.055f * std::pow(l, 1.0f / 2.4f) - 0.055f;
            toSrgb[i] = uint8_t(std::clamp(c * 255.0f + 0.5f, 0.0f, 255.0f));
        }
    }
};
const SrgbTables& srgbTables() {
    static const SrgbTables tables;
    return tables;
}

// 2x2 box filter of a square RGBA8 level.
std::vector<uint8_t> halve(const std::vector<uint8_t>& src, uint32_t size, bool srgb) {
    uint32_t half = std::max(size / 2, 1u);
    std::vector<uint8_t> dst(size_t(half) * half * 4);
    const SrgbTables& t = srgbTables();
    for (uint32_t y = 0; y < half; ++y)
        for (uint32_t x = 0; x < half; ++x)
            for (int c = 0; c < 4; ++c) {
                auto at = [&](uint32_t dx, uint32_t dy) {
                    uint32_t sx = std::min(2 * x + dx, size - 1),
                             sy = std::min(2 * y + dy, size - 1);
                    return src[(size_t(sy) * size + sx) * 4 + c];
                };
                uint8_t a = at(0, 0), b = at(1, 0), d = at(0, 1), e = at(1, 1);
                uint8_t out;
                if (srgb && c < 3) {
                    float l =
                        0.25f * (t.toLinear[a] + t.toLinear[b] + t.toLinear[d] + t.toLinear[e]);
                    out = t.toSrgb[std::min(int(l * 4096.0f), 4095)];
                } else {
                    out = uint8_t((unsigned(a) + b + d + e + 2) / 4);
                }
                dst[(size_t(y) * half + x) * 4 + c] = out;
            }
    return dst;
}

// Bilinear resample of an image to size x size (images that are not square powers of two).
std::vector<uint8_t> resample(const Texture& t, uint32_t size) {
    std::vector<uint8_t> out(size_t(size) * size * 4);
    for (uint32_t y = 0; y < size; ++y)
        for (uint32_t x = 0; x < size; ++x) {
            float fx = (float(x) + 0.5f) * float(t.width) / float(size) - 0.5f;
            float fy = (float(y) + 0.5f) * float(t.height) / float(size) - 0.5f;
            int x0 = std::clamp(int(std::floor(fx)), 0, int(t.width) - 1);
            int y0 = std::clamp(int(std::floor(fy)), 0, int(t.height) - 1);
            int x1 = std::min(x0 + 1, int(t.width) - 1), y1 = std::min(y0 + 1, int(t.height) - 1);
            float ax = std::clamp(fx - float(x0), 0.0f, 1.0f),
                  ay = std::clamp(fy - float(y0), 0.0f, 1.0f);
            for (int c = 0; c < 4; ++c) {
                auto px = [&](int xx, int yy) {
                    return float(t.rgba8[(size_t(yy) * t.width + xx) * 4 + c]);
                };
                float top = px(x0, y0) + (px(x1, y0) - px(x0, y0)) * ax;
                float bottom = px(x0, y1) + (px(x1, y1) - px(x0, y1)) * ax;
                out[(size_t(y) * size + x) * 4 + c] = uint8_t(top + (bottom - top) * ay + 0.5f);
            }
        }
    return out;
}

uint64_t levelBytes(BlockFormat format, uint32_t side) {
    return encodedBytes(format, side, side);
}

// An encoded level (texels or 4x4 blocks, row-major) in tile order: tiles row-major, each tile's
// rows contiguous (levels smaller than a tile are one tile of their own size).
std::vector<uint8_t> tiled(const std::vector<uint8_t>& level, uint32_t size, BlockFormat format) {
    const uint32_t unit = blockSide(format), bytes = blockBytes(format);
    const uint32_t across = (size + unit - 1) / unit; // blocks (texels) per row
    const uint32_t tile = std::max(std::min(size, kTexturePackTile) / unit, 1u);
    std::vector<uint8_t> out(level.size());
    size_t o = 0;
    for (uint32_t ty = 0; ty < across; ty += tile)
        for (uint32_t tx = 0; tx < across; tx += tile)
            for (uint32_t y = 0; y < tile; ++y) {
                std::memcpy(&out[o], &level[(size_t(ty + y) * across + tx) * bytes],
                            size_t(tile) * bytes);
                o += size_t(tile) * bytes;
            }
    return out;
}

int writeAll(int fd, const void* data, size_t size) {
    const char* bytes = static_cast<const char*>(data);
    while (size > 0) {
        ssize_t n = ::write(fd, bytes, size);
        if (n < 0) {
            if (errno == EINTR) continue;
            return errno;
        }
        bytes += n, size -= size_t(n);
    }
    return 0;
}

bool preadAll(int fd, void* dst, size_t size, uint64_t offset) {
    char* bytes = static_cast<char*>(dst);
    while (size > 0) {
        ssize_t n = ::pread(fd, bytes, size, off_t(offset));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        bytes += n, size -= size_t(n), offset += uint64_t(n);
    }
    return true;
}

} // namespace

uint32_t packedTextureSize(const Texture& t) {
    uint32_t side = std::max({t.width, t.height, 1u});
    uint32_t size = 1;
    while (size < side && size < kTexturePackMaxSize) size *= 2;
    return size;
}

std::vector<bool> srgbTextures(const Scene& scene) {
    std::vector<bool> srgb(scene.textures.size(), false);
    for (size_t i = 0; i < scene.textures.size(); ++i) srgb[i] = scene.textures[i].srgb;
    for (const Material& m : scene.materials)
        for (int32_t index : {m.baseColorTexture, m.emissiveTexture})
            if (index >= 0 && size_t(index) < srgb.size()) srgb[index] = true;
    return srgb;
}

std::vector<BlockFormat> packedTextureFormats(const Scene& scene, TextureCompression compression) {
    return std::vector<BlockFormat>(scene.textures.size(), compression == TextureCompression::Bc
                                                               ? BlockFormat::Bc7
                                                               : BlockFormat::Rgba8);
}

BakeKey texturePackKey(const Scene& scene, TextureCompression compression) {
    std::vector<bool> srgb = srgbTextures(scene);
    std::vector<BlockFormat> formats = packedTextureFormats(scene, compression);
    std::vector<uint64_t> words = {kTexturePackVersion, kTexturePackTile, scene.textures.size()};
    for (size_t i = 0; i < scene.textures.size(); ++i) {
        const Texture& t = scene.textures[i];
        words.insert(words.end(),
                     {t.width, t.height, uint64_t(srgb[i]), uint64_t(formats[i]), t.procedural.kind,
                      t.procedural.seed, hashBytes(t.rgba8.data(), t.rgba8.size(), 7)});
    }
    const size_t bytes = words.size() * sizeof(uint64_t);
    return {hashBytes(words.data(), bytes, 0x243F6A8885A308D3ull),
            hashBytes(words.data(), bytes, 0x13198A2E03707344ull)};
}

std::string texturePackPath(const std::string& cacheDir, const BakeKey& key) {
    return cacheDir + "/textures-" + key.hex() + ".bin";
}

// The RGBA8 level 0 of a texture at its packed size.
static std::vector<uint8_t> levelZero(const Texture& t, uint32_t size) {
    if (t.procedural.kind != 0) {
        std::vector<uint8_t> level(size_t(size) * size * 4);
        generateProceduralTexture(t.procedural, size, level.data());
        return level;
    }
    if (t.width == size && t.height == size) return t.rgba8;
    return resample(t, size);
}

// Says how far a long encode has come, at most every few seconds.
struct EncodeProgress {
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now(), last = start;
    uint64_t done = 0, total = 0; // RGBA8 bytes of every level
    void advance(uint64_t bytes, size_t texture, size_t textures) {
        done += bytes;
        auto now = std::chrono::steady_clock::now();
        if (now - last < std::chrono::seconds(5)) return;
        last = now;
        SHADEL_INFO("texture streaming file: encoded %zu of %zu textures (%.0f of %.0f MiB)",
                    texture, textures, double(done) / 1048576.0, double(total) / 1048576.0);
    }
    double seconds() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
};

// Writes the whole file through fd (header and directory last, once the checksums and PSNRs are
// known). Returns 0 or the errno of the first failure; *seconds: the time it took.
static int writePackTo(int fd, const Scene& scene, TextureCompression compression,
                       double* seconds) {
    std::vector<bool> srgb = srgbTextures(scene);
    std::vector<BlockFormat> formats = packedTextureFormats(scene, compression);
    std::vector<uint32_t> sizes;
    for (const Texture& t : scene.textures) sizes.push_back(packedTextureSize(t));
    BakeKey key = texturePackKey(scene, compression);

    // Layout first (it depends only on sizes and formats), so the data streams out in one pass.
    std::vector<uint8_t> directory(directoryBytes(sizes));
    uint64_t offset = sizeof(FileHeader) + directory.size();
    std::vector<LevelRecord> levels;
    EncodeProgress progress;
    for (size_t i = 0; i < sizes.size(); ++i)
        for (uint32_t l = 0; l < levelCount(sizes[i]); ++l) {
            uint32_t side = std::max(sizes[i] >> l, 1u);
            levels.push_back({offset, levelBytes(formats[i], side), 0});
            offset += levelBytes(formats[i], side);
            progress.total += uint64_t(side) * side * 4;
        }
    const uint64_t fileSize = offset;
    std::vector<float> psnr(sizes.size(), 99.0f);
    std::unique_ptr<WorkerPool> pool;
    if (compression != TextureCompression::None)
        pool = std::make_unique<WorkerPool>(std::max(1u, std::thread::hardware_concurrency()));

    int error = 0;
    if (::lseek(fd, off_t(sizeof(FileHeader) + directory.size()), SEEK_SET) < 0) error = errno;
    size_t levelIndex = 0;
    for (size_t i = 0; i < scene.textures.size() && error == 0; ++i) {
        uint32_t size = sizes[i];
        std::vector<uint8_t> level = levelZero(scene.textures[i], size);
        for (uint32_t l = 0; l < levelCount(size) && error == 0; ++l) {
            uint32_t side = std::max(size >> l, 1u);
            if (l > 0) level = halve(level, side * 2, srgb[i]);
            std::vector<uint8_t> encoded =
                encodeImage(formats[i], level.data(), side, side, pool.get());
            if (l == 0 && formats[i] != BlockFormat::Rgba8) {
                std::vector<uint8_t> decoded = decodeImage(formats[i], encoded.data(), side, side);
                psnr[i] = float(imagePsnr(level.data(), decoded.data(), size_t(side) * side,
                                          blockFormatChannels(formats[i])));
            }
            std::vector<uint8_t> tiles = tiled(encoded, side, formats[i]);
            levels[levelIndex].checksum = hashBytes(tiles.data(), tiles.size(), 0);
            ++levelIndex;
            error = writeAll(fd, tiles.data(), tiles.size());
            progress.advance(uint64_t(side) * side * 4, i, sizes.size());
        }
    }
    // The directory.
    size_t o = 0;
    levelIndex = 0;
    for (size_t i = 0; i < sizes.size(); ++i) {
        TextureRecord rec{
            sizes[i], levelCount(sizes[i]), uint32_t(srgb[i]), uint32_t(formats[i]), psnr[i], 0};
        std::memcpy(&directory[o], &rec, sizeof rec), o += sizeof rec;
        for (uint32_t l = 0; l < rec.levels; ++l, ++levelIndex)
            std::memcpy(&directory[o], &levels[levelIndex], sizeof(LevelRecord)),
                o += sizeof(LevelRecord);
    }
    FileHeader header{};
    std::memcpy(header.magic, kMagic, sizeof kMagic);
    header.version = kTexturePackVersion;
    header.endianTag = kEndianTag;
    header.keyLo = key.lo, header.keyHi = key.hi;
    header.tileSize = kTexturePackTile;
    header.textureCount = uint32_t(sizes.size());
    header.directoryBytes = directory.size();
    header.directoryChecksum = hashBytes(directory.data(), directory.size(), 0);
    header.fileSize = fileSize;
    if (error == 0 && ::lseek(fd, 0, SEEK_SET) < 0) error = errno;
    if (error == 0) error = writeAll(fd, &header, sizeof header);
    if (error == 0) error = writeAll(fd, directory.data(), directory.size());
    *seconds = progress.seconds();
    if (error == 0 && pool)
        SHADEL_INFO("texture streaming file: %zu textures (%.1f MiB RGBA8 with MIPs) block-"
                    "compressed in %.2f s (%.1f MB/s, %u threads)",
                    sizes.size(), double(progress.total) / 1048576.0, *seconds,
                    double(progress.total) / 1e6 / std::max(*seconds, 1e-9), pool->threads());
    return error;
}

bool buildTexturePack(const Scene& scene, const std::string& path, std::string* why,
                      TextureCompression compression) {
    namespace fs = std::filesystem;
    std::string scratch;
    std::string& reason = why ? *why : scratch;
    std::error_code ec;
    fs::path target(path);
    if (target.has_parent_path()) fs::create_directories(target.parent_path(), ec);
    static std::atomic<unsigned long long> counter{0};
    std::string temp = (target.parent_path() / format(".%s.tmp.%d.%llu", target.filename().c_str(),
                                                      int(::getpid()), counter.fetch_add(1)))
                           .string();
    int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) {
        reason = path + ": " + std::strerror(errno);
        return false;
    }
    double seconds = 0.0;
    int error = writePackTo(fd, scene, compression, &seconds);
    // Delayed allocation: a full disk may only show at fsync or close.
    if (error == 0 && ::fsync(fd) != 0 && errno != EINVAL) error = errno;
    if (::close(fd) != 0 && error == 0) error = errno;
    if (error == 0 && ::rename(temp.c_str(), path.c_str()) != 0) error = errno;
    if (error != 0) {
        ::unlink(temp.c_str());
        reason = path + ": " + std::strerror(error);
        return false;
    }
    return true;
}

// Opens a streaming file for reading: a regular file of this user's, never through a link and
// never waiting on a pipe. Returns the descriptor, or -1 and why not.
static int openPackFile(const std::string& path, std::string& reason) {
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
    if (fd < 0) {
        reason = errno == ENOENT  ? "missing"
                 : errno == ELOOP ? "a symbolic link"
                                  : std::string("cannot open: ") + std::strerror(errno);
        return -1;
    }
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
        reason = "not a regular file";
    else if (st.st_uid != ::geteuid())
        reason = format("owned by user %u, not this user", unsigned(st.st_uid));
    else
        return fd;
    ::close(fd);
    return -1;
}

// Reads and checks the header and directory of the file open at fd (see openTexturePack).
static bool readPack(int fd, const std::string& path, const BakeKey& key, TexturePack& out,
                     std::string& reason, bool verifyData) {
    struct stat st {};
    if (::fstat(fd, &st) != 0) {
        reason = std::string("cannot stat: ") + std::strerror(errno);
        return false;
    }
    const uint64_t fileBytes = uint64_t(st.st_size);
    FileHeader header{};
    if (fileBytes < sizeof header || !preadAll(fd, &header, sizeof header, 0)) {
        reason = "truncated header";
        return false;
    }
    if (std::memcmp(header.magic, kMagic, sizeof kMagic) != 0) {
        reason = "bad magic";
        return false;
    }
    if (header.version != kTexturePackVersion || header.endianTag != kEndianTag) {
        reason = format("stale format version %u (want %u)", header.version, kTexturePackVersion);
        return false;
    }
    if (header.keyLo != key.lo || header.keyHi != key.hi) {
        reason = "key mismatch (stale: the scene's textures changed)";
        return false;
    }
    if (header.fileSize != fileBytes) {
        reason = format("truncated or oversized (%llu bytes, header says %llu)",
                        (unsigned long long)fileBytes, (unsigned long long)header.fileSize);
        return false;
    }
    if (header.tileSize != kTexturePackTile || header.textureCount > (1u << 20) ||
        header.directoryBytes > fileBytes - sizeof header) {
        reason = "bad header fields";
        return false;
    }
    std::vector<uint8_t> directory(header.directoryBytes);
    if (!preadAll(fd, directory.data(), directory.size(), sizeof header) ||
        hashBytes(directory.data(), directory.size(), 0) != header.directoryChecksum) {
        reason = "directory checksum mismatch";
        return false;
    }
    TexturePack pack;
    pack.path = path;
    pack.key = key;
    pack.fileSize = fileBytes;
    // Every level must lie in the data section, in order, without overlap.
    uint64_t cursor = sizeof header + header.directoryBytes;
    size_t o = 0;
    for (uint32_t i = 0; i < header.textureCount; ++i) {
        TextureRecord rec{};
        if (directory.size() - o < sizeof rec) {
            reason = "directory too short";
            return false;
        }
        std::memcpy(&rec, &directory[o], sizeof rec), o += sizeof rec;
        if (rec.size == 0 || rec.size > kTexturePackMaxSize || (rec.size & (rec.size - 1)) != 0 ||
            rec.levels != levelCount(rec.size) || rec.srgb > 1 ||
            rec.format > uint32_t(BlockFormat::Bc5) || !(rec.psnr >= 0.0f && rec.psnr <= 99.0f) ||
            (directory.size() - o) / sizeof(LevelRecord) < rec.levels) {
            reason = format("texture %u: bad directory entry", i);
            return false;
        }
        PackedTexture t;
        t.size = rec.size;
        t.srgb = rec.srgb != 0;
        t.format = BlockFormat(rec.format);
        t.psnr = rec.psnr;
        for (uint32_t l = 0; l < rec.levels; ++l) {
            LevelRecord lr{};
            std::memcpy(&lr, &directory[o], sizeof lr), o += sizeof lr;
            uint32_t side = std::max(rec.size >> l, 1u);
            if (lr.bytes != levelBytes(t.format, side) || lr.offset != cursor ||
                lr.offset > fileBytes || lr.bytes > fileBytes - lr.offset) {
                reason = format("texture %u level %u: outside the file or misplaced", i, l);
                return false;
            }
            cursor += lr.bytes;
            t.levels.push_back({side, lr.offset, lr.bytes, lr.checksum});
        }
        pack.textures.push_back(std::move(t));
    }
    if (o != directory.size() || cursor != fileBytes) {
        reason = "directory does not cover the file";
        return false;
    }
    if (verifyData) {
        std::vector<uint8_t> buffer;
        for (size_t i = 0; i < pack.textures.size(); ++i)
            for (const PackedLevel& level : pack.textures[i].levels) {
                buffer.resize(level.bytes);
                if (!readPackedLevel(fd, level, buffer.data(), &reason)) {
                    reason = format("texture %zu level %u: %s", i, level.size, reason.c_str());
                    return false;
                }
            }
    }
    out = std::move(pack);
    return true;
}

bool openTexturePack(const std::string& path, const BakeKey& key, TexturePack& out,
                     std::string* why, bool verifyData) {
    std::string scratch;
    std::string& reason = why ? *why : scratch;
    int fd = openPackFile(path, reason);
    if (fd < 0) return false;
    bool ok = readPack(fd, path, key, out, reason, verifyData);
    ::close(fd);
    return ok;
}

// Writes the pack into an anonymous in-memory file: the fallback when there is no cache folder or
// it cannot be written. Throws if even that fails.
static TexturePack buildTexturePackInMemory(const Scene& scene, const BakeKey& key,
                                            TextureCompression compression) {
    int fd = ::memfd_create("shadel-texture-streaming", MFD_CLOEXEC);
    if (fd < 0)
        throw std::runtime_error(std::string("texture streaming file in memory: ") +
                                 std::strerror(errno));
    TexturePack pack;
    std::string why;
    double seconds = 0.0;
    if (int error = writePackTo(fd, scene, compression, &seconds); error != 0)
        why = std::strerror(error);
    else if (!readPack(fd, "(memory)", key, pack, why, false))
        why = "unreadable right after writing: " + why;
    if (!why.empty()) {
        ::close(fd);
        throw std::runtime_error("texture streaming file in memory: " + why);
    }
    pack.fd = fd;
    pack.encodeSeconds = seconds;
    return pack;
}

TexturePack openOrBuildTexturePack(const Scene& scene, const std::string& cacheDir,
                                   TextureCompression compression) {
    BakeKey key = texturePackKey(scene, compression);
    uint64_t texels = 0;
    for (const Texture& t : scene.textures)
        texels += uint64_t(packedTextureSize(t)) * packedTextureSize(t);
    const double mib = double(texels * 4) / 1048576.0;
    if (cacheDir.empty()) {
        SHADEL_INFO("building the texture streaming file of %zu textures (%.0f MiB at level 0) "
                    "in memory: no cache folder",
                    scene.textures.size(), mib);
        return buildTexturePackInMemory(scene, key, compression);
    }
    std::string path = texturePackPath(cacheDir, key);
    TexturePack pack;
    std::string why;
    if (int fd = openPackFile(path, why); fd >= 0) {
        if (readPack(fd, path, key, pack, why, true)) {
            ::futimens(fd, nullptr); // a use, for least-recently-used eviction
            pack.fd = fd;
            return pack;
        }
        ::close(fd);
    }
    if (why != "missing")
        SHADEL_WARN("texture streaming file %s unusable (%s): rebuilding", path.c_str(),
                    why.c_str());
    SHADEL_INFO("building the texture streaming file of %zu textures (%.0f MiB at level 0): %s",
                scene.textures.size(), mib, path.c_str());
    const auto start = std::chrono::steady_clock::now();
    if (!buildTexturePack(scene, path, &why, compression)) {
        SHADEL_WARN("texture streaming file not cached (%s): streaming from memory", why.c_str());
        return buildTexturePackInMemory(scene, key, compression);
    }
    int fd = openPackFile(path, why);
    if (fd < 0 || !readPack(fd, path, key, pack, why, false)) {
        if (fd >= 0) ::close(fd);
        throw std::runtime_error("texture streaming file " + path +
                                 " unreadable right after writing: " + why);
    }
    pack.fd = fd;
    pack.encodeSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return pack;
}

bool readPackedLevel(int fd, const PackedLevel& level, uint8_t* dst, std::string* why) {
    if (!preadAll(fd, dst, level.bytes, level.offset)) {
        if (why) *why = "read error or truncated";
        return false;
    }
    if (hashBytes(dst, level.bytes, 0) != level.checksum) {
        if (why) *why = "checksum mismatch";
        return false;
    }
    return true;
}

} // namespace shadel
