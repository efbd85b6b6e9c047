// Whole images through the block codecs, and the PSNR of the quality figures.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "bake/block_compression/block_compression.h"
#include "core/worker_pool.h"

namespace shadel {

const char* blockFormatName(BlockFormat format) {
    switch (format) {
    case BlockFormat::Rgba8:
        return "rgba8";
    case BlockFormat::Bc7:
        return "bc7";
    case BlockFormat::Bc4:
        return "bc4";
    case BlockFormat::Bc5:
        return "bc5";
    }
    return "?";
}

uint32_t blockSide(BlockFormat format) {
    return format == BlockFormat::Rgba8 ? 1 : 4;
}

uint32_t blockBytes(BlockFormat format) {
    return format == BlockFormat::Bc4 ? 8 : format == BlockFormat::Rgba8 ? 4 : 16;
}

uint64_t encodedBytes(BlockFormat format, uint32_t width, uint32_t height) {
    const uint32_t side = blockSide(format);
    return uint64_t((width + side - 1) / side) * ((height + side - 1) / side) * blockBytes(format);
}

uint32_t blockFormatChannels(BlockFormat format) {
    return format == BlockFormat::Bc4 ? 0x1u : format == BlockFormat::Bc5 ? 0x3u : 0xFu;
}

std::vector<uint8_t> encodeImage(BlockFormat format, const uint8_t* rgba, uint32_t width,
                                 uint32_t height, WorkerPool* pool) {
    if (format == BlockFormat::Rgba8) return {rgba, rgba + size_t(width) * height * 4};
    const uint32_t bw = (width + 3) / 4, bh = (height + 3) / 4, bytes = blockBytes(format);
    std::vector<uint8_t> out(size_t(bw) * bh * bytes);
    auto row = [&](uint32_t by, uint32_t) {
        uint8_t texels[64];
        for (uint32_t bx = 0; bx < bw; ++bx) {
            for (uint32_t i = 0; i < 16; ++i) { // texels past the edge repeat the edge texel
                uint32_t x = std::min(bx * 4 + (i & 3), width - 1);
                uint32_t y = std::min(by * 4 + (i >> 2), height - 1);
                std::memcpy(texels + 4 * i, rgba + (size_t(y) * width + x) * 4, 4);
            }
            uint8_t* dst = out.data() + (size_t(by) * bw + bx) * bytes;
            if (format == BlockFormat::Bc7) {
                encodeBc7Block(texels, dst);
            } else {
                encodeBc4Block(texels, 4, dst);
                if (format == BlockFormat::Bc5) encodeBc4Block(texels + 1, 4, dst + 8);
            }
        }
    };
    if (pool && pool->threads() > 1 && bh > 1)
        pool->parallelFor(bh, row);
    else
        for (uint32_t by = 0; by < bh; ++by) row(by, 0);
    return out;
}

std::vector<uint8_t> decodeImage(BlockFormat format, const uint8_t* data, uint32_t width,
                                 uint32_t height) {
    if (format == BlockFormat::Rgba8) return {data, data + size_t(width) * height * 4};
    std::vector<uint8_t> out(size_t(width) * height * 4);
    const uint32_t bw = (width + 3) / 4, bh = (height + 3) / 4, bytes = blockBytes(format);
    uint8_t texels[64];
    for (uint32_t by = 0; by < bh; ++by)
        for (uint32_t bx = 0; bx < bw; ++bx) {
            const uint8_t* src = data + (size_t(by) * bw + bx) * bytes;
            if (format == BlockFormat::Bc7) {
                decodeBc7Block(src, texels);
            } else {
                uint8_t r[16], g[16] = {};
                decodeBc4Block(src, r);
                if (format == BlockFormat::Bc5) decodeBc4Block(src + 8, g);
                for (int i = 0; i < 16; ++i)
                    texels[4 * i] = r[i], texels[4 * i + 1] = g[i], texels[4 * i + 2] = 0,
                               texels[4 * i + 3] = 255;
            }
            for (uint32_t i = 0; i < 16; ++i) {
                uint32_t x = bx * 4 + (i & 3), y = by * 4 + (i >> 2);
                if (x < width && y < height)
                    std::memcpy(out.data() + (size_t(y) * width + x) * 4, texels + 4 * i, 4);
            }
        }
    return out;
}

double imagePsnr(const uint8_t* a, const uint8_t* b, size_t texels, uint32_t channels) {
    double sum = 0.0;
    size_t count = 0;
    for (size_t i = 0; i < texels; ++i)
        for (uint32_t c = 0; c < 4; ++c)
            if (channels & (1u << c)) {
                double d = double(a[4 * i + c]) - double(b[4 * i + c]);
                sum += d * d;
                ++count;
            }
    if (count == 0 || sum == 0.0) return 99.0;
    return 10.0 * std::log10(255.0 * 255.0 / (sum / double(count)));
}

} // namespace shadel
