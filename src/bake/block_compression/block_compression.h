#pragma once
// Block compression of RGBA8 texels into the BC formats the GPU samples directly, and their
// decoders (the quality figures and the tests read them). 4x4 texel blocks, row-major; texels
// past an image's edge (sides that are not multiples of 4) repeat the edge texel.
//
//   BC7: 16 bytes a block (1 byte a texel), RGBA. The encoder tries mode 6 (one subset, RGBA
//        7.7.7.7 + p-bit, 4-bit indices); for opaque blocks modes 1 and 3 (two subsets, RGB, 3-
//        and 2-bit indices) over the best two of the 64 partitions by a principal-axis estimate;
//        for blocks with alpha modes 5 (RGB and alpha indexed apart) and 7 (two subsets, RGBA);
//        a constant block is exact (mode 5, per-channel optimal endpoint pairs). Endpoints come
//        from the principal axis, refined by least squares on the chosen indices, p-bits tried.
//   BC4: 8 bytes a block, one channel (red); BC5: 16 bytes, two (red, green), each a BC4 block.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace shadel {

class WorkerPool;

enum class BlockFormat : uint32_t { Rgba8 = 0, Bc7 = 1, Bc4 = 2, Bc5 = 3 };

const char* blockFormatName(BlockFormat format);
// Texels per block side (1 for RGBA8) and bytes per block (per texel for RGBA8).
uint32_t blockSide(BlockFormat format);
uint32_t blockBytes(BlockFormat format);
// Bytes of a width x height image (whole blocks).
uint64_t encodedBytes(BlockFormat format, uint32_t width, uint32_t height);
// The channels a format keeps, as a mask (bit c = channel c of RGBA).
uint32_t blockFormatChannels(BlockFormat format);

void encodeBc7Block(const uint8_t rgba[64], uint8_t out[16]);
void decodeBc7Block(const uint8_t block[16], uint8_t rgba[64]);
// One channel of 16 texels read with a stride of `stride` bytes.
void encodeBc4Block(const uint8_t* values, uint32_t stride, uint8_t out[8]);
void decodeBc4Block(const uint8_t block[8], uint8_t values[16]);

// Encodes a whole image (RGBA8, row-major). The pool, when given, shares the block rows.
std::vector<uint8_t> encodeImage(BlockFormat format, const uint8_t* rgba, uint32_t width,
                                 uint32_t height, WorkerPool* pool = nullptr);
// Decodes to RGBA8 as the GPU samples it: BC4 as (r, 0, 0, 255), BC5 as (r, g, 0, 255).
std::vector<uint8_t> decodeImage(BlockFormat format, const uint8_t* data, uint32_t width,
                                 uint32_t height);
// PSNR in dB over the channels in `channels` (a mask), 8-bit peak; 99 when identical.
double imagePsnr(const uint8_t* a, const uint8_t* b, size_t texels, uint32_t channels);

} // namespace shadel
