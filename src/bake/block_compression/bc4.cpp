// BC4 (one channel) blocks: two 8-bit endpoints and 3-bit indices. BC5 is two of them.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "bake/block_compression/block_compression.h"

namespace shadel {
namespace {

// The eight values a block's endpoints decode to (r0 > r1: six between; else four between,
// then 0 and 255), rounded to 8 bits as a UNORM conversion does.
void bc4Palette(int r0, int r1, int palette[8]) {
    palette[0] = r0, palette[1] = r1;
    if (r0 > r1) {
        for (int i = 2; i < 8; ++i) palette[i] = (2 * ((8 - i) * r0 + (i - 1) * r1) + 7) / 14;
    } else {
        for (int i = 2; i < 6; ++i) palette[i] = (2 * ((6 - i) * r0 + (i - 1) * r1) + 5) / 10;
        palette[6] = 0, palette[7] = 255;
    }
}

struct Bc4Fit {
    int r0 = 0, r1 = 0;
    uint8_t index[16] = {};
    uint32_t error = ~0u;
};

void tryEndpoints(const int v[16], int r0, int r1, Bc4Fit& best) {
    int palette[8];
    bc4Palette(r0, r1, palette);
    Bc4Fit t;
    t.r0 = r0, t.r1 = r1, t.error = 0;
    for (int i = 0; i < 16; ++i) {
        uint32_t e = ~0u;
        for (int k = 0; k < 8; ++k) {
            uint32_t d = uint32_t((palette[k] - v[i]) * (palette[k] - v[i]));
            if (d < e) e = d, t.index[i] = uint8_t(k);
        }
        t.error += e;
    }
    if (t.error < best.error) best = t;
}

// The interpolation position (0 at r0, 1 at r1) of each palette entry of the eight-value mode.
float position(int k) {
    return k == 0 ? 0.0f : k == 1 ? 1.0f : float(k - 1) / 7.0f;
}

} // namespace

void encodeBc4Block(const uint8_t* values, uint32_t stride, uint8_t out[8]) {
    int v[16], lo = 255, hi = 0, innerLo = 255, innerHi = 0;
    bool extremes = false;
    for (int i = 0; i < 16; ++i) {
        v[i] = values[size_t(i) * stride];
        lo = std::min(lo, v[i]), hi = std::max(hi, v[i]);
        if (v[i] == 0 || v[i] == 255) {
            extremes = true;
        } else {
            innerLo = std::min(innerLo, v[i]), innerHi = std::max(innerHi, v[i]);
        }
    }
    Bc4Fit best;
    if (lo == hi) {
        tryEndpoints(v, lo, lo, best);
    } else {
        tryEndpoints(v, hi, lo, best);
        // Least squares on the chosen positions, then the nearest endpoints around it.
        float a = 0, b = 0, c = 0, x0 = 0, x1 = 0;
        for (int i = 0; i < 16; ++i) {
            float t = position(best.index[i]), s = 1.0f - t;
            a += s * s, b += s * t, c += t * t, x0 += s * float(v[i]), x1 += t * float(v[i]);
        }
        float det = a * c - b * b;
        if (std::fabs(det) > 1e-6f) {
            int r0 = std::clamp(int(std::lround((c * x0 - b * x1) / det)), 0, 255);
            int r1 = std::clamp(int(std::lround((a * x1 - b * x0) / det)), 0, 255);
            for (int d0 = -1; d0 <= 1; ++d0)
                for (int d1 = -1; d1 <= 1; ++d1) {
                    int e0 = std::clamp(r0 + d0, 0, 255), e1 = std::clamp(r1 + d1, 0, 255);
                    if (e0 > e1) tryEndpoints(v, e0, e1, best);
                }
        }
        if (extremes && innerLo <= innerHi) tryEndpoints(v, innerLo, innerHi, best);
    }
    out[0] = uint8_t(best.r0), out[1] = uint8_t(best.r1);
    uint64_t bits = 0;
    for (int i = 0; i < 16; ++i) bits |= uint64_t(best.index[i]) << (3 * i);
    for (int i = 0; i < 6; ++i) out[2 + i] = uint8_t(bits >> (8 * i));
}

void decodeBc4Block(const uint8_t block[8], uint8_t values[16]) {
    int palette[8];
    bc4Palette(block[0], block[1], palette);
    uint64_t bits = 0;
    for (int i = 0; i < 6; ++i) bits |= uint64_t(block[2 + i]) << (8 * i);
    for (int i = 0; i < 16; ++i) values[i] = uint8_t(palette[(bits >> (3 * i)) & 7u]);
}

} // namespace shadel
