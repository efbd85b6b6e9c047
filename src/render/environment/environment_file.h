#pragma once
// Equirectangular environment files: Radiance .hdr (stb_image) and OpenEXR .exr (tinyexr).
#include <cstdint>
#include <string>
#include <vector>

#include "render/environment/equirect.h"

namespace shadel {

// Largest accepted image (and the smallest: 8 x 4).
constexpr uint32_t kEnvironmentMaxWidth = 16384;
constexpr uint32_t kEnvironmentMaxHeight = 8192;

// The file's bytes; throws InputError "<path>: <reason>" when it cannot be read.
std::vector<uint8_t> readEnvironmentFile(const std::string& path);

// Decodes the bytes of `path` (.hdr or .exr by extension) into linear RGB radiance. Throws
// InputError "<path>: <reason>" for an unknown extension, a file that does not decode, a size
// outside 8x4..16384x8192, a width:height far from 2:1, or no finite positive texel. Negative
// and non-finite texels read as 0 (counted in a warning).
EquirectImage decodeEnvironmentFile(const std::string& path, const std::vector<uint8_t>& bytes);

} // namespace shadel
