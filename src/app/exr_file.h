#pragma once
// OpenEXR encoding (tinyexr) for HDR colour and depth: `--out FILE.exr` and `--capture`.
#include <cstdint>
#include <string>
#include <vector>

namespace shadel {

// `channels` interleaved floats per pixel (1: Z for depth-like data, 3: RGB, 4: RGBA), stored
// as 32-bit float channels, ZIP-compressed. Throws InputError naming `what` when it fails.
std::vector<uint8_t> encodeExr(const std::vector<float>& pixels, uint32_t width, uint32_t height,
                               uint32_t channels, const std::string& what);
// Decodes an EXR written by encodeExr (tests, tools): RGBA floats, missing channels 0 / A = 1.
std::vector<float> decodeExrRgba(const std::vector<uint8_t>& file, uint32_t& width,
                                 uint32_t& height);

} // namespace shadel
