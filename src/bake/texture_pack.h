#pragma once
// The streaming file of a scene's textures (streamed textures): every texture as a
// square power-of-two image with all its pre-filtered MIP levels, RGBA8 or block-compressed
// (bake/block_compression: BC7 by default, 1 byte a texel), each level stored as fixed-size
// tiles (kTexturePackTile^2 texels, row-major tiles, each tile's rows of texels or 4x4 blocks
// contiguous) so a level uploads as one copy region per tile and a sparse image could page single
// tiles in. Levels are filtered from the RGBA8 texels, then each is encoded on its own.
//
// File: header { magic "SHDLTEXS", format version, endianness tag, 128-bit key, tile size,
// texture count, directory size + checksum, file size } | directory | level data. The directory
// lists per texture its side, level count, sRGB flag, block format and the PSNR of its encoded
// level 0 against its RGBA8 texels, and per level its offset, size and
// checksum. Opening checks all of it against the file (sizes, bounds, overlaps, checksums), so a
// corrupt, truncated or stale file is rejected with a reason and rebuilt, and no reader ever
// indexes past what the file holds. Written to a temporary file and renamed into place.
#include <cstdint>
#include <string>
#include <vector>

#include "bake/bake_cache.h"
#include "bake/block_compression/block_compression.h"
#include "scene/scene.h"

namespace shadel {

// Bump whenever the file's bytes for the same scene can change.
constexpr uint32_t kTexturePackVersion = 2;
constexpr uint32_t kTexturePackTile = 128;
constexpr uint32_t kTexturePackMaxSize = 8192;

struct PackedLevel {
    uint32_t size = 0; // side in texels
    uint64_t offset = 0, bytes = 0, checksum = 0;
};

// --texture-compression: none stores RGBA8, bc block-compresses.
enum class TextureCompression : uint8_t { None, Bc };

struct PackedTexture {
    uint32_t size = 0; // level 0 side (power of two)
    bool srgb = false;
    BlockFormat format = BlockFormat::Rgba8;
    float psnr = 99.0f;              // dB, level 0 decoded against its RGBA8 texels (99: identical)
    std::vector<PackedLevel> levels; // level 0 (full) .. the 1x1 level
};

struct TexturePack {
    std::string path; // "(memory)" when built in memory
    int fd = -1;      // open for reading (openOrBuildTexturePack only; the caller closes it)
    BakeKey key;
    uint64_t fileSize = 0;
    std::vector<PackedTexture> textures; // one per Scene::textures entry
    double encodeSeconds = 0.0;          // building it (0: opened from the cache)
};

// The side a texture is stored at: the next power of two of its larger side, at most
// kTexturePackMaxSize (non-square and non-power-of-two images are resampled to it).
uint32_t packedTextureSize(const Texture& texture);
// Whether each scene texture holds colour (sRGB): flagged, or a base colour / emissive map.
std::vector<bool> srgbTextures(const Scene& scene);
// The block format of each scene texture: RGBA8 without compression; with it BC7 for every
// texture, colour and data alike (a layered-cache slot serves any texture of its size, so all
// share one format; BC5 normal maps would also lose the length Toksvig filtering reads).
std::vector<BlockFormat> packedTextureFormats(const Scene& scene, TextureCompression compression);
// Hash of everything the file's bytes depend on (texels or recipes, sizes, formats, version).
BakeKey texturePackKey(const Scene& scene,
                       TextureCompression compression = TextureCompression::None);
std::string texturePackPath(const std::string& cacheDir, const BakeKey& key);

// Writes the file (false + *why on failure).
bool buildTexturePack(const Scene& scene, const std::string& path, std::string* why,
                      TextureCompression compression = TextureCompression::None);
// Reads and checks the header and directory against `key` and the file's size; with
// verifyData, also every level's checksum. False + *why ("missing", "truncated", ...) else.
bool openTexturePack(const std::string& path, const BakeKey& key, TexturePack& out,
                     std::string* why, bool verifyData = true);
// The scene's pack from the cache folder, built (or rebuilt, with a warning naming the reason)
// when missing or unusable, and open (TexturePack::fd). Without a cache folder, or when the file
// cannot be written there (read-only, full), the pack is built in memory with a warning. Throws
// std::runtime_error only if that fails too.
TexturePack openOrBuildTexturePack(const Scene& scene, const std::string& cacheDir,
                                   TextureCompression compression = TextureCompression::None);

// Reads one level's tiles into dst (level.bytes) through an open descriptor and checks its
// checksum. Safe to call from several threads at once (pread).
bool readPackedLevel(int fd, const PackedLevel& level, uint8_t* dst, std::string* why);

} // namespace shadel
