#pragma once
// On-disk cache of baked meshes, keyed by a content hash of the mesh and the bake settings.
//
// File: header { magic "SHDLBAKE", format version, endianness tag, 128-bit key, payload size,
// payload checksum } then the payload. A file whose magic, version, key, size, checksum or
// contents do not check out is rejected (the caller warns and rebakes), never trusted. Writes go
// to a unique temporary file that is renamed over the target, so readers never see a partial
// file and concurrent writers of the same key cannot corrupt each other.
#include <cstdint>
#include <string>
#include <vector>

#include "bake/bake.h"

namespace shadel {

// Bump whenever the bake output for the same input can change (algorithm or layout).
constexpr uint32_t kBakeFormatVersion = 7; // 2: conformal charts, outline packing, stretch;
                                           // 3: charts bounded by the mesh density CV;
                                           // 4: waste-aware packing of few charts;
                                           // 5: 22.5-degree orientations;
                                           // 6: wider growth cones tried on few charts;
                                           // 7: vertices carry a second UV set

struct BakeKey {
    uint64_t lo = 0, hi = 0;
    bool operator==(const BakeKey&) const = default;
    std::string hex() const;
};

// Hash of positions, normals, indices, the settings that affect the bake and kBakeFormatVersion.
BakeKey bakeKey(const Mesh& mesh, const BakeSettings& settings);

std::string bakeCachePath(const std::string& cacheDir, const BakeKey& key);

// Loads a cached bake for `mesh`. Returns false and sets *why if the file is missing (why =
// "missing") or unusable (truncated, corrupted, stale, inconsistent with the mesh).
bool readBakeCache(const std::string& path, const BakeKey& key, const Mesh& mesh, BakedMesh& out,
                   std::string* why);
// The bytes of a cache file holding `payload` for `key` (a valid header and checksum): what
// writeBakeCache writes, exposed so that tests and the fuzzer can hand the reader any payload.
std::vector<uint8_t> bakeCacheFileBytes(const BakeKey& key, const std::vector<uint8_t>& payload);
// Atomically writes a cache file (creating directories). Returns false and sets *why on failure.
bool writeBakeCache(const std::string& path, const BakeKey& key, const BakedMesh& baked,
                    std::string* why);

// 64-bit hash of a byte range (used for keys and payload checksums).
uint64_t hashBytes(const void* data, size_t size, uint64_t seed);

} // namespace shadel
