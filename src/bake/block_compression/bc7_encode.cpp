// The BC7 encoder (block_compression.h): per block, candidate modes fitted and the one with the
// least squared error over RGBA kept.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <utility>

#include "bake/block_compression/bc7_tables.h"
#include "bake/block_compression/block_compression.h"

namespace shadel {
namespace {

using bc7::Mode;

// A mode 6 block with at most this squared error (summed over the 64 values: per-channel
// MSE 1, about 48 dB) skips the two-subset search.
constexpr uint32_t kGoodEnough = 64;
// Two-subset partitions fitted in full, the best by the principal-axis estimate.
constexpr int kPartitionCandidates = 2;

uint32_t widen(uint32_t v, uint32_t bits) {
    if (bits >= 8) return v;
    v <<= 8 - bits;
    return v | (v >> bits);
}

// The 8-bit value of a quantized endpoint channel (bits wide, plus a p-bit when hasP).
int endpointValue(int q, int p, int bits, bool hasP) {
    return hasP ? int(widen(uint32_t((q << 1) | p), uint32_t(bits + 1)))
                : int(widen(uint32_t(q), uint32_t(bits)));
}

// The nearest quantized value to v with p-bit p.
int quantize(float v, int p, int bits, bool hasP) {
    const int n = bits + (hasP ? 1 : 0), top = (1 << bits) - 1;
    const float scaled = v / 255.0f * float((1 << n) - 1);
    int q =
        hasP ? int(std::floor((scaled - float(p)) * 0.5f + 0.5f)) : int(std::floor(scaled + 0.5f));
    int best = std::clamp(q, 0, top);
    float bestError = 1e30f;
    for (int c = q - 1; c <= q + 1; ++c) {
        if (c < 0 || c > top) continue;
        float d = float(endpointValue(c, p, bits, hasP)) - v;
        if (d * d < bestError) bestError = d * d, best = c;
    }
    return best;
}

struct Pixels {
    int v[16][4];
};

// One subset's fit over channels [c0, c1): quantized endpoints, p-bits, the members' indices.
struct SubsetFit {
    int q[2][4] = {};
    int p[2] = {0, 0};
    uint8_t index[16] = {}; // by member order
    uint32_t error = ~0u;
};

struct FitSpec {
    int c0, c1; // channels fitted
    int colorBits, alphaBits;
    int pbits; // 0 none, 1 shared, 2 per endpoint
    int indexBits;
};

int channelBits(const FitSpec& f, int c) {
    return c < 3 ? f.colorBits : f.alphaBits;
}

// Mean and principal axis of the members over the fitted channels (power iteration).
void principalAxis(const Pixels& px, const uint8_t* members, int n, const FitSpec& f, float mean[4],
                   float axis[4]) {
    for (int c = 0; c < 4; ++c) mean[c] = 0.0f, axis[c] = 0.0f;
    for (int i = 0; i < n; ++i)
        for (int c = f.c0; c < f.c1; ++c) mean[c] += float(px.v[members[i]][c]);
    for (int c = f.c0; c < f.c1; ++c) mean[c] /= float(n);
    float cov[4][4] = {};
    for (int i = 0; i < n; ++i)
        for (int a = f.c0; a < f.c1; ++a)
            for (int b = a; b < f.c1; ++b)
                cov[a][b] +=
                    (float(px.v[members[i]][a]) - mean[a]) * (float(px.v[members[i]][b]) - mean[b]);
    for (int a = f.c0; a < f.c1; ++a)
        for (int b = f.c0; b < a; ++b) cov[a][b] = cov[b][a];
    int widest = f.c0;
    for (int c = f.c0; c < f.c1; ++c)
        if (cov[c][c] > cov[widest][widest]) widest = c;
    axis[widest] = 1.0f;
    for (int it = 0; it < 6; ++it) {
        float next[4] = {}, len = 0.0f;
        for (int a = f.c0; a < f.c1; ++a) {
            for (int b = f.c0; b < f.c1; ++b) next[a] += cov[a][b] * axis[b];
            len += next[a] * next[a];
        }
        if (len < 1e-12f) break;
        len = 1.0f / std::sqrt(len);
        for (int c = f.c0; c < f.c1; ++c) axis[c] = next[c] * len;
    }
}

// Per index width, the nearest palette index to each position 0..64 along the endpoints.
struct NearestWeight {
    uint8_t index[3][65];
    NearestWeight() {
        for (int bits = 2; bits <= 4; ++bits)
            for (int t = 0; t <= 64; ++t) {
                const uint8_t* w = bc7::weights(uint32_t(bits));
                int best = 0;
                for (int k = 1; k < (1 << bits); ++k)
                    if (std::abs(int(w[k]) - t) < std::abs(int(w[best]) - t)) best = k;
                index[bits - 2][t] = uint8_t(best);
            }
    }
};

// Indices and error for quantized endpoints: each member takes the nearest palette entry, found
// by its position along the endpoints and checked against the entries either side (rounding
// puts the palette only nearly on that line).
uint32_t assignIndices(const Pixels& px, const uint8_t* members, int n, const FitSpec& f,
                       const int e0[4], const int e1[4], uint8_t* index) {
    static const NearestWeight nearest;
    const uint8_t* w = bc7::weights(uint32_t(f.indexBits));
    const int entries = 1 << f.indexBits;
    int palette[16][4];
    int d[4] = {}, dd = 0;
    for (int c = f.c0; c < f.c1; ++c) {
        d[c] = e1[c] - e0[c];
        dd += d[c] * d[c];
    }
    for (int k = 0; k < entries; ++k)
        for (int c = f.c0; c < f.c1; ++c)
            palette[k][c] = ((64 - w[k]) * e0[c] + w[k] * e1[c] + 32) >> 6;
    const float scale = dd > 0 ? 64.0f / float(dd) : 0.0f;
    uint32_t total = 0;
    for (int i = 0; i < n; ++i) {
        const int* v = px.v[members[i]];
        int dot = 0;
        for (int c = f.c0; c < f.c1; ++c) dot += (v[c] - e0[c]) * d[c];
        const int t = std::clamp(int(float(dot) * scale + 0.5f), 0, 64);
        const int k0 = nearest.index[f.indexBits - 2][t];
        uint32_t best = ~0u;
        int bestK = k0;
        for (int k = std::max(k0 - 1, 0); k <= std::min(k0 + 1, entries - 1); ++k) {
            uint32_t e = 0;
            for (int c = f.c0; c < f.c1; ++c) {
                int diff = palette[k][c] - v[c];
                e += uint32_t(diff * diff);
            }
            if (e < best) best = e, bestK = k;
        }
        index[i] = uint8_t(bestK);
        total += best;
    }
    return total;
}

// Quantizes float endpoints under every allowed p-bit choice and keeps the best in `fit`.
void tryEndpoints(const Pixels& px, const uint8_t* members, int n, const FitSpec& f,
                  const float e0[4], const float e1[4], SubsetFit& fit) {
    static const int kChoices[4][2] = {{0, 0}, {1, 1}, {0, 1}, {1, 0}};
    const int choices = f.pbits == 0 ? 1 : f.pbits == 1 ? 2 : 4;
    for (int ch = 0; ch < choices; ++ch) {
        SubsetFit t;
        t.p[0] = kChoices[ch][0], t.p[1] = kChoices[ch][1];
        int v0[4] = {}, v1[4] = {};
        for (int c = f.c0; c < f.c1; ++c) {
            const int bits = channelBits(f, c);
            t.q[0][c] = quantize(e0[c], t.p[0], bits, f.pbits != 0);
            t.q[1][c] = quantize(e1[c], t.p[1], bits, f.pbits != 0);
            v0[c] = endpointValue(t.q[0][c], t.p[0], bits, f.pbits != 0);
            v1[c] = endpointValue(t.q[1][c], t.p[1], bits, f.pbits != 0);
        }
        t.error = assignIndices(px, members, n, f, v0, v1, t.index);
        if (t.error < fit.error) fit = t;
    }
}

// Principal-axis endpoints, then least-squares refinements on the chosen indices.
SubsetFit fitSubset(const Pixels& px, const uint8_t* members, int n, const FitSpec& f) {
    float mean[4], axis[4];
    principalAxis(px, members, n, f, mean, axis);
    float lo = 1e30f, hi = -1e30f;
    for (int i = 0; i < n; ++i) {
        float t = 0.0f;
        for (int c = f.c0; c < f.c1; ++c) t += (float(px.v[members[i]][c]) - mean[c]) * axis[c];
        lo = std::min(lo, t), hi = std::max(hi, t);
    }
    float e0[4] = {}, e1[4] = {};
    for (int c = f.c0; c < f.c1; ++c) {
        e0[c] = std::clamp(mean[c] + lo * axis[c], 0.0f, 255.0f);
        e1[c] = std::clamp(mean[c] + hi * axis[c], 0.0f, 255.0f);
    }
    SubsetFit best;
    tryEndpoints(px, members, n, f, e0, e1, best);
    const uint8_t* w = bc7::weights(uint32_t(f.indexBits));
    for (int iteration = 0; iteration < 2 && best.error > 0; ++iteration) {
        float a = 0, b = 0, cc = 0, x0[4] = {}, x1[4] = {};
        for (int i = 0; i < n; ++i) {
            const float t = float(w[best.index[i]]) / 64.0f, s = 1.0f - t;
            a += s * s, b += s * t, cc += t * t;
            for (int c = f.c0; c < f.c1; ++c)
                x0[c] += s * float(px.v[members[i]][c]), x1[c] += t * float(px.v[members[i]][c]);
        }
        const float det = a * cc - b * b;
        if (std::fabs(det) < 1e-6f) break;
        for (int c = f.c0; c < f.c1; ++c) {
            e0[c] = std::clamp((cc * x0[c] - b * x1[c]) / det, 0.0f, 255.0f);
            e1[c] = std::clamp((a * x1[c] - b * x0[c]) / det, 0.0f, 255.0f);
        }
        const uint32_t before = best.error;
        tryEndpoints(px, members, n, f, e0, e1, best);
        if (best.error >= before) break;
    }
    return best;
}

// A whole candidate block of one of the modes without rotation (0, 1, 2, 3, 6, 7).
struct Candidate {
    uint32_t mode = 0, partition = 0, error = ~0u;
    int q[3][2][4] = {};
    int p[3][2] = {};
    uint8_t index[16] = {};
    uint8_t index2[16] = {}; // mode 5's alpha indices
};

struct BitWriter {
    uint8_t* bytes;
    uint32_t position = 0;
    void put(uint32_t v, uint32_t bits) {
        for (uint32_t i = 0; i < bits; ++i, ++position)
            if ((v >> i) & 1u) bytes[position >> 3] |= uint8_t(1u << (position & 7));
    }
};

void writeBlock(const Candidate& cand, uint8_t out[16]) {
    const Mode& m = bc7::kModes[cand.mode];
    std::memset(out, 0, 16);
    BitWriter w{out};
    w.put(1u << cand.mode, cand.mode + 1);
    w.put(cand.partition, m.partitionBits);
    w.put(0, m.rotationBits);
    w.put(0, m.indexSelectionBits);
    for (int c = 0; c < 3; ++c)
        for (uint32_t s = 0; s < m.subsets; ++s)
            for (int e = 0; e < 2; ++e) w.put(uint32_t(cand.q[s][e][c]), m.colorBits);
    for (uint32_t s = 0; s < m.subsets && m.alphaBits; ++s)
        for (int e = 0; e < 2; ++e) w.put(uint32_t(cand.q[s][e][3]), m.alphaBits);
    for (uint32_t s = 0; s < m.subsets; ++s) {
        if (m.pbits == 2) w.put(uint32_t(cand.p[s][0]), 1), w.put(uint32_t(cand.p[s][1]), 1);
        if (m.pbits == 1) w.put(uint32_t(cand.p[s][0]), 1);
    }
    for (uint32_t i = 0; i < 16; ++i) {
        bool anchor = false;
        for (uint32_t s = 0; s < m.subsets; ++s)
            anchor |= bc7::anchorOf(m.subsets, cand.partition, s) == i;
        w.put(cand.index[i], m.indexBits - (anchor ? 1 : 0));
    }
    for (uint32_t i = 0; i < 16 && m.indexBits2; ++i)
        w.put(cand.index2[i], m.indexBits2 - (i == 0));
}

// An anchor texel's index must have its top bit clear: otherwise swap that subset's endpoints
// and mirror its indices (the same colours).
void fixAnchors(Candidate& cand, bool alphaApart) {
    const Mode& m = bc7::kModes[cand.mode];
    const int top = (1 << m.indexBits) - 1;
    for (uint32_t s = 0; s < m.subsets; ++s) {
        const uint32_t a = bc7::anchorOf(m.subsets, cand.partition, s);
        if (cand.index[a] <= top / 2) continue;
        for (int c = 0; c < (alphaApart ? 3 : 4); ++c) std::swap(cand.q[s][0][c], cand.q[s][1][c]);
        std::swap(cand.p[s][0], cand.p[s][1]);
        for (uint32_t i = 0; i < 16; ++i)
            if (bc7::subsetOf(m.subsets, cand.partition, i) == s)
                cand.index[i] = uint8_t(top - cand.index[i]);
    }
    if (alphaApart && cand.index2[0] > ((1 << m.indexBits2) - 1) / 2) {
        std::swap(cand.q[0][0][3], cand.q[0][1][3]);
        for (uint8_t& i : cand.index2) i = uint8_t((1 << m.indexBits2) - 1 - i);
    }
}

// Squared error of the channels a mode does not store (alpha 255 in modes 0-3).
uint32_t alphaError(const Pixels& px) {
    uint32_t e = 0;
    for (const auto& v : px.v) e += uint32_t((255 - v[3]) * (255 - v[3]));
    return e;
}

// A mode with subsets (no rotation) fitted for one partition.
Candidate fitMode(const Pixels& px, uint32_t mode, uint32_t partition) {
    const Mode& m = bc7::kModes[mode];
    const FitSpec f{0, m.alphaBits ? 4 : 3, m.colorBits, m.alphaBits, m.pbits, m.indexBits};
    Candidate cand;
    cand.mode = mode, cand.partition = partition;
    cand.error = m.alphaBits ? 0 : alphaError(px);
    for (uint32_t s = 0; s < m.subsets; ++s) {
        uint8_t members[16];
        int n = 0;
        for (uint32_t i = 0; i < 16; ++i)
            if (bc7::subsetOf(m.subsets, partition, i) == s) members[n++] = uint8_t(i);
        SubsetFit fit = fitSubset(px, members, n, f);
        cand.error += fit.error;
        std::memcpy(cand.q[s], fit.q, sizeof fit.q);
        cand.p[s][0] = fit.p[0], cand.p[s][1] = fit.p[1];
        for (int i = 0; i < n; ++i) cand.index[members[i]] = fit.index[i];
    }
    return cand;
}

// Mode 5: colour (7 bits) and alpha (8 bits) each with their own 2-bit indices.
Candidate fitMode5(const Pixels& px) {
    uint8_t all[16];
    for (int i = 0; i < 16; ++i) all[i] = uint8_t(i);
    SubsetFit color = fitSubset(px, all, 16, {0, 3, 7, 8, 0, 2});
    SubsetFit alpha = fitSubset(px, all, 16, {3, 4, 7, 8, 0, 2});
    Candidate cand;
    cand.mode = 5;
    cand.error = color.error + alpha.error;
    for (int e = 0; e < 2; ++e) {
        for (int c = 0; c < 3; ++c) cand.q[0][e][c] = color.q[e][c];
        cand.q[0][e][3] = alpha.q[e][3];
    }
    std::memcpy(cand.index, color.index, 16);
    std::memcpy(cand.index2, alpha.index, 16);
    return cand;
}

// Per 8-bit value, the pair of 7-bit endpoints whose 2-bit index 1 (weight 21) decodes to it
// most closely: a constant block in mode 5.
struct ConstantTable {
    std::array<std::array<uint8_t, 2>, 256> pair{};
    ConstantTable() {
        for (int v = 0; v < 256; ++v) {
            int best = 1 << 30;
            for (int lo = 0; lo < 128; ++lo)
                for (int hi = 0; hi < 128; ++hi) {
                    int a = int(widen(uint32_t(lo), 7)), b = int(widen(uint32_t(hi), 7));
                    int d = ((64 - 21) * a + 21 * b + 32) / 64 - v;
                    if (d * d < best) best = d * d, pair[v] = {uint8_t(lo), uint8_t(hi)};
                }
        }
    }
};

Candidate constantBlock(const int color[4]) {
    static const ConstantTable table;
    Candidate cand;
    cand.mode = 5;
    cand.error = 0;
    for (int c = 0; c < 3; ++c) {
        cand.q[0][0][c] = table.pair[color[c]][0], cand.q[0][1][c] = table.pair[color[c]][1];
        int a = int(widen(table.pair[color[c]][0], 7)), b = int(widen(table.pair[color[c]][1], 7));
        int d = ((64 - 21) * a + 21 * b + 32) / 64 - color[c];
        cand.error += uint32_t(16 * d * d);
    }
    cand.q[0][0][3] = cand.q[0][1][3] = color[3];
    std::fill(std::begin(cand.index), std::end(cand.index), uint8_t(1));
    return cand;
}

// The two-subset partitions ranked by the squared distance of the texels from their subsets'
// principal axes (RGB, from each subset's raw moments), the best `count` returned.
void bestPartitions(const Pixels& px, int count, uint32_t* out) {
    // Per texel: r, g, b, rr, rg, rb, gg, gb, bb.
    float m[16][9], total[9] = {};
    for (int i = 0; i < 16; ++i) {
        const float r = float(px.v[i][0]), g = float(px.v[i][1]), b = float(px.v[i][2]);
        const float v[9] = {r, g, b, r * r, r * g, r * b, g * g, g * b, b * b};
        for (int k = 0; k < 9; ++k) m[i][k] = v[k], total[k] += v[k];
    }
    auto residual = [](const float* s, float n) {
        if (n < 2.0f) return 0.0f;
        const float mr = s[0] / n, mg = s[1] / n, mb = s[2] / n;
        const float c[3][3] = {{s[3] / n - mr * mr, s[4] / n - mr * mg, s[5] / n - mr * mb},
                               {s[4] / n - mr * mg, s[6] / n - mg * mg, s[7] / n - mg * mb},
                               {s[5] / n - mr * mb, s[7] / n - mg * mb, s[8] / n - mb * mb}};
        float a[3] = {1.0f, 1.0f, 1.0f}, lambda = 0.0f;
        for (int it = 0; it < 4; ++it) {
            float next[3], len = 0.0f;
            for (int r = 0; r < 3; ++r) {
                next[r] = c[r][0] * a[0] + c[r][1] * a[1] + c[r][2] * a[2];
                len += next[r] * next[r];
            }
            if (len < 1e-12f) return 0.0f;
            len = std::sqrt(len);
            lambda = len / std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
            for (int r = 0; r < 3; ++r) a[r] = next[r] / len;
        }
        return std::max(c[0][0] + c[1][1] + c[2][2] - lambda, 0.0f) * n;
    };
    std::pair<float, uint32_t> scores[64];
    for (uint32_t part = 0; part < 64; ++part) {
        float second[9] = {}, first[9];
        float n = 0.0f;
        for (uint32_t i = 0; i < 16; ++i)
            if ((bc7::kPartitions2[part] >> i) & 1u) {
                for (int k = 0; k < 9; ++k) second[k] += m[i][k];
                n += 1.0f;
            }
        for (int k = 0; k < 9; ++k) first[k] = total[k] - second[k];
        scores[part] = {residual(first, 16.0f - n) + residual(second, n), part};
    }
    std::partial_sort(scores, scores + count, scores + 64);
    for (int i = 0; i < count; ++i) out[i] = scores[i].second;
}

} // namespace

void encodeBc7Block(const uint8_t rgba[64], uint8_t out[16]) {
    Pixels px;
    bool opaque = true, constant = true;
    for (int i = 0; i < 16; ++i)
        for (int c = 0; c < 4; ++c) {
            px.v[i][c] = rgba[4 * i + c];
            constant &= rgba[4 * i + c] == rgba[c];
        }
    for (int i = 0; i < 16; ++i) opaque &= px.v[i][3] == 255;
    Candidate best;
    if (constant) {
        best = constantBlock(px.v[0]);
    } else {
        best = fitMode(px, 6, 0);
        if (best.error > kGoodEnough) {
            if (!opaque) {
                Candidate c5 = fitMode5(px);
                if (c5.error < best.error) best = c5;
            }
            uint32_t parts[kPartitionCandidates];
            bestPartitions(px, kPartitionCandidates, parts);
            // Opaque: RGB with 3-bit (6-bit endpoints) or 2-bit indices; else RGBA.
            static const uint32_t kOpaqueModes[] = {1, 3}, kAlphaModes[] = {7};
            const uint32_t* modes = opaque ? kOpaqueModes : kAlphaModes;
            for (uint32_t part : parts)
                for (uint32_t m = 0; m < (opaque ? 2u : 1u); ++m) {
                    Candidate c = fitMode(px, modes[m], part);
                    if (c.error < best.error) best = c;
                }
        }
    }
    fixAnchors(best, best.mode == 5);
    writeBlock(best, out);
}

} // namespace shadel
