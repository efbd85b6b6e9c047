// The BC7 decoder: every mode, as the format defines it (the reference for the encoder's
// tests and the quality figures).
#include <utility>

#include "bake/block_compression/bc7_tables.h"
#include "bake/block_compression/block_compression.h"

namespace shadel {
namespace {

struct BitReader {
    const uint8_t* bytes;
    uint32_t position = 0;
    uint32_t read(uint32_t bits) {
        uint32_t v = 0;
        for (uint32_t i = 0; i < bits; ++i, ++position)
            v |= uint32_t((bytes[position >> 3] >> (position & 7)) & 1u) << i;
        return v;
    }
};

// An n-bit endpoint value widened to 8 bits by repeating its top bits.
uint32_t widen(uint32_t v, uint32_t bits) {
    if (bits >= 8) return v;
    v <<= 8 - bits;
    return v | (v >> bits);
}

} // namespace

void decodeBc7Block(const uint8_t block[16], uint8_t rgba[64]) {
    using namespace bc7;
    BitReader r{block};
    uint32_t mode = 0;
    while (mode < 8 && r.read(1) == 0) ++mode;
    if (mode == 8) { // reserved: every texel transparent black
        for (int i = 0; i < 64; ++i) rgba[i] = 0;
        return;
    }
    const Mode& m = kModes[mode];
    const uint32_t partition = r.read(m.partitionBits);
    const uint32_t rotation = r.read(m.rotationBits);
    const uint32_t indexSelection = r.read(m.indexSelectionBits);
    uint32_t ep[3][2][4] = {};
    for (uint32_t c = 0; c < 3; ++c)
        for (uint32_t s = 0; s < m.subsets; ++s)
            for (uint32_t e = 0; e < 2; ++e) ep[s][e][c] = r.read(m.colorBits);
    for (uint32_t s = 0; s < m.subsets && m.alphaBits; ++s)
        for (uint32_t e = 0; e < 2; ++e) ep[s][e][3] = r.read(m.alphaBits);
    uint32_t p[3][2] = {};
    for (uint32_t s = 0; s < m.subsets; ++s) {
        if (m.pbits == 2)
            p[s][0] = r.read(1), p[s][1] = r.read(1);
        else if (m.pbits == 1)
            p[s][0] = p[s][1] = r.read(1);
    }
    const uint32_t extra = m.pbits ? 1 : 0;
    for (uint32_t s = 0; s < m.subsets; ++s)
        for (uint32_t e = 0; e < 2; ++e) {
            for (uint32_t c = 0; c < 3; ++c)
                ep[s][e][c] =
                    widen((ep[s][e][c] << extra) | (extra ? p[s][e] : 0), m.colorBits + extra);
            ep[s][e][3] = m.alphaBits ? widen((ep[s][e][3] << extra) | (extra ? p[s][e] : 0),
                                              m.alphaBits + extra)
                                      : 255;
        }
    uint32_t index[16], index2[16] = {};
    for (uint32_t i = 0; i < 16; ++i) {
        bool anchor = false;
        for (uint32_t s = 0; s < m.subsets; ++s) anchor |= anchorOf(m.subsets, partition, s) == i;
        index[i] = r.read(m.indexBits - (anchor ? 1 : 0));
    }
    for (uint32_t i = 0; i < 16 && m.indexBits2; ++i) index2[i] = r.read(m.indexBits2 - (i == 0));
    for (uint32_t i = 0; i < 16; ++i) {
        const uint32_t s = subsetOf(m.subsets, partition, i);
        uint32_t colorIndex = index[i], alphaIndex = index[i];
        uint32_t colorBits = m.indexBits, alphaBits = m.indexBits;
        if (m.indexBits2) {
            alphaIndex = index2[i], alphaBits = m.indexBits2;
            if (indexSelection) std::swap(colorIndex, alphaIndex), std::swap(colorBits, alphaBits);
        }
        const uint32_t wc = weights(colorBits)[colorIndex], wa = weights(alphaBits)[alphaIndex];
        uint8_t* out = rgba + 4 * i;
        for (uint32_t c = 0; c < 3; ++c)
            out[c] = uint8_t(((64 - wc) * ep[s][0][c] + wc * ep[s][1][c] + 32) >> 6);
        out[3] = uint8_t(((64 - wa) * ep[s][0][3] + wa * ep[s][1][3] + 32) >> 6);
        if (rotation) std::swap(out[3], out[rotation - 1]);
    }
}

} // namespace shadel
