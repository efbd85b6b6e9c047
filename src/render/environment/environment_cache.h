#pragma once
// On-disk cache of prefiltered environment maps, keyed by content: a hash of the source (the
// file's bytes, or the sky's or hemisphere's parameters), the map sizes and
// kEnvironmentFormatVersion.
//
// File: header { magic "SHDLENVM", format version, endianness tag, 128-bit key, payload size,
// payload checksum } then the payload: an image count, then per image its width, height and
// RGB float texels. A file whose header, size, checksum, image sizes or values (finite,
// non-negative) do not check out is rejected (the caller rebuilds and rewrites it), never
// trusted. Written atomically (core/atomic_file.h).
#include <cstdint>
#include <string>
#include <vector>

#include "bake/bake_cache.h"
#include "render/environment/equirect.h"

namespace shadel {

// Bump whenever the maps for the same source can change (sky model, filters, layout).
constexpr uint32_t kEnvironmentFormatVersion = 3;

std::string environmentCachePath(const std::string& cacheDir, const BakeKey& key);

// Loads the images of a cache file. Returns false and sets *why ("missing", or what is wrong).
bool readEnvironmentCache(const std::string& path, const BakeKey& key,
                          std::vector<EquirectImage>& images, std::string* why);
// Writes atomically (creating the folder). Returns false and sets *why on failure.
bool writeEnvironmentCache(const std::string& path, const BakeKey& key,
                           const std::vector<EquirectImage>& images, std::string* why);

} // namespace shadel
