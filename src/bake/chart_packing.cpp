#include "bake/chart_packing.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace shadel {
namespace {

// Coordinates come from float-free double math, but the UVs the renderer rasterizes are floats:
// anything within this many shadels of a column or row border counts as touching it.
constexpr double kTouchEpsilon = 1e-3;
constexpr uint32_t kEmpty = std::numeric_limits<uint32_t>::max();
// Column offsets tried per chart and orientation before refining around the best one.
constexpr uint32_t kMaxStridedPositions = 256;

uint32_t roundUp(uint32_t v, uint32_t granularity) {
    return (v + granularity - 1) / granularity * granularity;
}

int clampIndex(double v, int size) {
    return std::clamp(int(std::max(-1.0, std::min(v, 1e9))), 0, size - 1);
}

struct Candidate {
    uint64_t top = std::numeric_limits<uint64_t>::max();
    uint64_t waste = std::numeric_limits<uint64_t>::max();
    uint32_t x = 0, y = 0, orientation = 0;
    bool found = false;
};

// Bottom-left along the horizon: for every column offset and orientation, the chart sits as low
// as its bottom profile allows; the lowest top wins, then the least space left under the chart.
OutlinePack packAtWidth(const std::vector<std::array<ChartOutline, 4>>& outlines,
                        const std::vector<uint32_t>& order, uint32_t binWidth,
                        uint32_t granularity) {
    std::vector<uint32_t> horizon(binWidth, 0);
    OutlinePack pack;
    pack.placements.resize(outlines.size());
    uint32_t right = 0, top = 0;
    for (uint32_t c : order) {
        Candidate best;
        for (uint32_t k = 0; k < 4; ++k) {
            const ChartOutline& o = outlines[c][k];
            if (o.width == 0 || o.width > binWidth) continue;
            uint32_t maxTop = 0;
            for (uint32_t i = 0; i < o.width; ++i)
                if (o.bottom[i] < o.top[i]) maxTop = std::max(maxTop, o.top[i]);
            // Every column offset on narrow bins; on wide ones a stride, then every offset
            // around the best strided one, which keeps packing linear in the chart count.
            uint32_t positions = binWidth - o.width + 1;
            uint32_t stride = std::max(1u, positions / kMaxStridedPositions);
            auto tryAt = [&](uint32_t x) {
                uint64_t y = 0;
                for (uint32_t i = 0; i < o.width; ++i) {
                    if (o.bottom[i] >= o.top[i]) continue;
                    if (horizon[x + i] > o.bottom[i])
                        y = std::max<uint64_t>(y, horizon[x + i] - o.bottom[i]);
                    if (y + maxTop > best.top) return;
                }
                uint64_t waste = 0;
                for (uint32_t i = 0; i < o.width; ++i)
                    if (o.bottom[i] < o.top[i]) waste += y + o.bottom[i] - horizon[x + i];
                uint64_t chartTop = y + maxTop;
                if (chartTop < best.top || (chartTop == best.top && waste < best.waste))
                    best = {chartTop, waste, x, uint32_t(y), k, true};
            };
            Candidate before = best;
            for (uint32_t x = 0; x < positions; x += stride) tryAt(x);
            if (stride > 1 && (best.x != before.x || best.orientation != before.orientation ||
                               best.found != before.found)) {
                uint32_t centre = best.x;
                uint32_t from = centre >= stride ? centre - stride + 1 : 0;
                uint32_t to = std::min(positions - 1, centre + stride - 1);
                for (uint32_t x = from; x <= to; ++x) tryAt(x);
            }
        }
        if (!best.found) return {};
        const ChartOutline& o = outlines[c][best.orientation];
        for (uint32_t i = 0; i < o.width; ++i)
            if (o.bottom[i] < o.top[i]) horizon[best.x + i] = best.y + o.top[i];
        pack.placements[c] = {best.x, best.y, best.orientation};
        for (uint32_t i = 0; i < o.width; ++i)
            if (o.bottom[i] < o.top[i]) right = std::max(right, best.x + i + 1);
        top = std::max(top, uint32_t(best.top));
    }
    pack.width = roundUp(std::max(right, 1u), granularity);
    pack.height = roundUp(std::max(top, 1u), granularity);
    return pack;
}

} // namespace

glm::dvec2 turnQuarter(glm::dvec2 p, glm::dvec2 content, uint32_t orientation) {
    switch (orientation & 3) {
    case 1:
        return {p.y, content.x - p.x};
    case 2:
        return {content.x - p.x, content.y - p.y};
    case 3:
        return {content.y - p.y, p.x};
    default:
        return p;
    }
}

ChartOutline chartOutline(const std::vector<glm::dvec2>& corners, glm::uvec2 content,
                          uint32_t gutter) {
    int cw = int(std::max(content.x, 1u)), ch = int(std::max(content.y, 1u));
    std::vector<uint32_t> lo(size_t(cw), kEmpty), hi(size_t(cw), 0);
    for (size_t t = 0; t + 2 < corners.size(); t += 3) {
        const glm::dvec2* p = &corners[t];
        double xmin = std::min({p[0].x, p[1].x, p[2].x}), xmax = std::max({p[0].x, p[1].x, p[2].x});
        int j0 = clampIndex(std::floor(xmin - kTouchEpsilon), cw);
        int j1 = clampIndex(std::ceil(xmax + kTouchEpsilon) - 1, cw);
        for (int j = j0; j <= j1; ++j) {
            // The triangle clipped to the column slab is a convex polygon whose vertices are the
            // clipped edge ends: their y range is the triangle's y range in the column.
            double s0 = j - kTouchEpsilon, s1 = j + 1 + kTouchEpsilon;
            double ymin = 1e300, ymax = -1e300;
            for (int e = 0; e < 3; ++e) {
                glm::dvec2 a = p[e], b = p[(e + 1) % 3];
                double t0 = 0, t1 = 1;
                if (a.x == b.x) {
                    if (a.x < s0 || a.x > s1) continue;
                } else {
                    t0 = (s0 - a.x) / (b.x - a.x), t1 = (s1 - a.x) / (b.x - a.x);
                    if (t0 > t1) std::swap(t0, t1);
                    t0 = std::max(t0, 0.0), t1 = std::min(t1, 1.0);
                    if (t0 > t1) continue;
                }
                for (double s : {t0, t1}) {
                    double y = a.y + (b.y - a.y) * s;
                    ymin = std::min(ymin, y), ymax = std::max(ymax, y);
                }
            }
            if (ymin > ymax) continue;
            int r0 = clampIndex(std::floor(ymin - kTouchEpsilon), ch);
            int r1 = clampIndex(std::ceil(ymax + kTouchEpsilon) - 1, ch);
            lo[size_t(j)] = std::min(lo[size_t(j)], uint32_t(r0));
            hi[size_t(j)] = std::max(hi[size_t(j)], uint32_t(r1) + 1);
        }
    }
    // Dilate by the gutter: outline column i sees content columns i - 2g .. i, and their rows
    // shifted up by g and grown by g both ways: [lo, hi + 2g) in outline rows.
    ChartOutline o;
    o.width = uint32_t(cw) + 2 * gutter;
    o.height = uint32_t(ch) + 2 * gutter;
    o.bottom.assign(o.width, 1);
    o.top.assign(o.width, 0);
    for (int i = 0; i < int(o.width); ++i) {
        uint32_t b = kEmpty, t = 0;
        for (int j = std::max(0, i - 2 * int(gutter)); j <= std::min(i, cw - 1); ++j) {
            if (lo[size_t(j)] == kEmpty) continue;
            b = std::min(b, lo[size_t(j)]);
            t = std::max(t, hi[size_t(j)] + 2 * gutter);
        }
        if (b != kEmpty) o.bottom[size_t(i)] = b, o.top[size_t(i)] = t;
    }
    return o;
}

OutlinePack packOutlines(const std::vector<std::array<ChartOutline, 4>>& outlines,
                         uint32_t granularity) {
    if (outlines.empty()) return {{}, granularity, granularity};
    double area = 0;
    uint32_t minWidthNeeded = 1;
    for (const auto& chart : outlines) {
        uint32_t narrowest = ~0u;
        for (const ChartOutline& o : chart)
            if (o.width > 0) narrowest = std::min(narrowest, o.width);
        minWidthNeeded = std::max(minWidthNeeded, narrowest);
        const ChartOutline& o = chart[0];
        for (uint32_t i = 0; i < o.width; ++i)
            if (o.bottom[i] < o.top[i]) area += double(o.top[i] - o.bottom[i]);
    }
    std::vector<uint32_t> order(outlines.size());
    std::iota(order.begin(), order.end(), 0u);
    // Big charts first (occupied area); ties by index keep the result deterministic.
    std::vector<double> chartArea(outlines.size(), 0.0);
    for (size_t c = 0; c < outlines.size(); ++c) {
        const ChartOutline& o = outlines[c][0];
        for (uint32_t i = 0; i < o.width; ++i)
            if (o.bottom[i] < o.top[i]) chartArea[c] += double(o.top[i] - o.bottom[i]);
    }
    std::stable_sort(order.begin(), order.end(),
                     [&](uint32_t a, uint32_t b) { return chartArea[a] > chartArea[b]; });
    double side = std::sqrt(area);
    OutlinePack best;
    double bestScore = 1e300;
    uint32_t lastWidth = 0;
    for (double factor : {0.95, 1.05, 1.15, 1.3, 1.5, 1.8}) {
        uint32_t width =
            roundUp(std::max(minWidthNeeded, uint32_t(std::ceil(side * factor))), granularity);
        if (width == lastWidth) continue;
        lastWidth = width;
        OutlinePack pack = packAtWidth(outlines, order, width, granularity);
        if (pack.width == 0) continue;
        double aspect =
            double(std::max(pack.width, pack.height)) / std::min(pack.width, pack.height);
        double score = double(pack.width) * pack.height * (aspect > 2.0 ? aspect / 2.0 : 1.0);
        if (score < bestScore) bestScore = score, best = std::move(pack);
    }
    return best;
}

} // namespace shadel
