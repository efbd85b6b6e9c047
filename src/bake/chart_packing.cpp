#include "bake/chart_packing.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <numeric>

namespace shadel {
namespace {

// UVs reach the renderer as floats: anything within this many shadels of a column or row border
// counts as touching it.
constexpr double kTouchEpsilon = 1e-3;
// Column offsets tried per chart and orientation before refining around the best one.
constexpr uint32_t kMaxStridedPositions = 48;
// Meshes with at most this many charts are packed with more orders and bin widths.
constexpr size_t kThoroughPackingCharts = 24;
// ... unless the quick pass already covers this much of the rect with outlines.
constexpr double kTightOutlineFill = 0.85;
// Meshes of at most this many charts are also packed waste-aware (packAtWidth): a position's score
// is its top plus kWasteWeight times the mean empty height left under the chart's columns.
constexpr size_t kWasteAwareCharts = 12;
constexpr double kWasteWeight = 1.0;
// Lifts of one chart while looking for a hole before it is put on top of its columns instead.
constexpr uint32_t kMaxLifts = 300;
// Bins wider than this many columns are searched on columns merged in groups (see coarsen).
constexpr uint32_t kCoarseColumns = 512;

uint32_t roundUp(uint32_t v, uint32_t granularity) {
    return (v + granularity - 1) / granularity * granularity;
}

int clampIndex(double v, int size) {
    return std::clamp(int(std::max(-1.0, std::min(v, 1e9))), 0, size - 1);
}

// Sorts runs and merges overlapping or touching ones, in place.
void mergeRuns(std::vector<glm::uvec2>& runs) {
    std::sort(runs.begin(), runs.end(),
              [](glm::uvec2 a, glm::uvec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    size_t out = 0;
    for (size_t i = 0; i < runs.size(); ++i) {
        if (out > 0 && runs[i].x <= runs[out - 1].y)
            runs[out - 1].y = std::max(runs[out - 1].y, runs[i].y);
        else
            runs[out++] = runs[i];
    }
    runs.resize(out);
}

// Occupied rows of every bin column: sorted disjoint runs.
class Occupancy {
public:
    explicit Occupancy(uint32_t width) : columns_(width) {}

    // Lowest lift >= `from` such that rows [lift + run.x, lift + run.y) of column x are free.
    uint64_t fitInColumn(uint32_t x, glm::uvec2 run, uint64_t from) const {
        const std::vector<glm::uvec2>& col = columns_[x];
        uint64_t begin = from + run.x;
        // First occupied run ending after `begin`; then climb over runs until the gap fits.
        auto it = std::upper_bound(col.begin(), col.end(), begin,
                                   [](uint64_t v, glm::uvec2 r) { return v < r.y; });
        for (; it != col.end() && it->x < begin + (run.y - run.x); ++it) begin = it->y;
        return begin - run.x;
    }

    // One past the highest occupied row of column x at or below `row` (0 if none).
    uint32_t floorBelow(uint32_t x, uint64_t row) const {
        const std::vector<glm::uvec2>& col = columns_[x];
        auto it = std::upper_bound(col.begin(), col.end(), row,
                                   [](uint64_t v, glm::uvec2 r) { return v < r.y; });
        return it == col.begin() ? 0u : std::prev(it)->y;
    }

    // One past the highest occupied row of column x.
    uint32_t top(uint32_t x) const { return columns_[x].empty() ? 0 : columns_[x].back().y; }

    void add(uint32_t x, glm::uvec2 run) {
        std::vector<glm::uvec2>& col = columns_[x];
        auto it = std::lower_bound(col.begin(), col.end(), run.x,
                                   [](glm::uvec2 r, uint32_t v) { return r.x < v; });
        size_t i = size_t(it - col.begin());
        col.insert(it, run);
        // Merge with touching neighbours so columns stay short.
        if (i + 1 < col.size() && col[i].y >= col[i + 1].x) {
            col[i].y = std::max(col[i].y, col[i + 1].y);
            col.erase(col.begin() + std::ptrdiff_t(i + 1));
        }
        if (i > 0 && col[i - 1].y >= col[i].x) {
            col[i - 1].y = std::max(col[i - 1].y, col[i].y);
            col.erase(col.begin() + std::ptrdiff_t(i));
        }
    }

private:
    std::vector<std::vector<glm::uvec2>> columns_;
};

struct Candidate {
    uint64_t top = std::numeric_limits<uint64_t>::max();
    double score = 1e300;
    uint32_t x = 0, y = 0, orientation = 0;
    bool found = false;
};

// Lowest y at which outline o placed at column x meets no occupied run, or > `limit` (the caller
// only cares below it). Every conflict lifts the chart to the end of the run it hit, so y only
// grows and the loop ends.
// Lowest y at which the outline sits above everything in its columns: always a fit.
uint64_t skylineFit(const Occupancy& occupancy, const ChartOutline& o, uint32_t x) {
    uint64_t y = 0;
    for (uint32_t i = 0; i < o.width; ++i)
        if (o.first[i] < o.first[i + 1] && occupancy.top(x + i) > o.runs[o.first[i]].x)
            y = std::max<uint64_t>(y, occupancy.top(x + i) - o.runs[o.first[i]].x);
    return y;
}

uint64_t lowestFit(const Occupancy& occupancy, const ChartOutline& o, uint32_t x, uint64_t limit) {
    uint64_t y = 0;
    uint32_t lifts = 0;
    // Columns are visited cyclically; the fit holds once every column passed since the last lift.
    uint32_t clean = 0;
    for (uint32_t i = 0; clean < o.width && y <= limit; i = i + 1 == o.width ? 0 : i + 1) {
        bool lifted = false;
        for (uint32_t k = o.first[i]; k < o.first[i + 1]; ++k) {
            uint64_t fit = occupancy.fitInColumn(x + i, o.runs[k], y);
            if (fit != y) {
                // Climbing through a densely packed stack costs a rescan per lift; past a few
                // lifts the holes below are too small anyway, so the chart goes on top.
                if (++lifts > kMaxLifts) return skylineFit(occupancy, o, x);
                y = fit;
                lifted = true;
                k = o.first[i] - 1; // earlier runs of this column may collide at the new height
            }
        }
        clean = lifted ? 1 : clean + 1;
    }
    return y;
}

// Column i of the coarse outline holds the runs of columns i*s .. i*s + s - 1 merged. Placed at
// multiples of s against an occupancy coarsened the same way it is conservative: where the coarse
// outline fits, the exact one fits at the same place or lower.
ChartOutline coarsen(const ChartOutline& o, uint32_t s) {
    ChartOutline c;
    c.width = (o.width + s - 1) / s;
    c.height = o.height;
    std::vector<glm::uvec2> merged;
    for (uint32_t i = 0; i < c.width; ++i) {
        c.first.push_back(uint32_t(c.runs.size()));
        merged.clear();
        for (uint32_t j = i * s; j < std::min(o.width, i * s + s); ++j)
            merged.insert(merged.end(), o.runs.begin() + o.first[j],
                          o.runs.begin() + o.first[j + 1]);
        mergeRuns(merged);
        c.runs.insert(c.runs.end(), merged.begin(), merged.end());
    }
    c.first.push_back(uint32_t(c.runs.size()));
    return c;
}

// Bottom-left over the occupancy: for every column offset and orientation the chart sits as low
// as its runs allow (possibly inside an earlier chart's hole); the lowest top wins. Wide bins are
// searched on coarse columns (at most kCoarseColumns), then the chart is dropped exactly.
OutlinePack packAtWidth(const std::vector<std::array<ChartOutline, kOrientations>>& outlines,
                        const std::vector<uint32_t>& order, uint32_t rectWidth, uint32_t gutter,
                        uint32_t granularity, double wasteWeight) {
    // Outlines may overhang the rect by the gutter: only content must stay inside.
    uint32_t binWidth = rectWidth + 2 * gutter;
    uint32_t s = std::max(1u, binWidth / kCoarseColumns);
    Occupancy fine(binWidth), coarseOccupancy((binWidth + s - 1) / s);
    const Occupancy& search = s == 1 ? fine : coarseOccupancy;
    std::vector<std::array<ChartOutline, kOrientations>> coarse;
    if (s > 1) {
        coarse.resize(outlines.size());
        for (size_t c = 0; c < outlines.size(); ++c)
            for (uint32_t k = 0; k < kOrientations; ++k)
                if (outlines[c][k].width > 0) coarse[c][k] = coarsen(outlines[c][k], s);
    }
    OutlinePack pack;
    pack.placements.resize(outlines.size());
    uint32_t right = 0, top = 0;
    for (uint32_t c : order) {
        Candidate best; // x in search columns
        for (uint32_t k = 0; k < kOrientations; ++k) {
            const ChartOutline& o = outlines[c][k];
            if (o.width == 0 || o.width > binWidth || o.runs.empty()) continue;
            const ChartOutline& so = s == 1 ? o : coarse[c][k];
            uint32_t maxTop = 0;
            for (const glm::uvec2& run : o.runs) maxTop = std::max(maxTop, run.y);
            auto tryAt = [&](uint32_t x) {
                if (wasteWeight > 0 && s == 1) {
                    // The score is at least the top: positions that cannot beat it are cut.
                    if (best.found && best.score <= double(maxTop)) return;
                    uint64_t limit = best.found ? uint64_t(best.score) - maxTop : ~0ull >> 2;
                    uint64_t y = lowestFit(search, so, x, limit);
                    if (y > limit) return;
                    double waste = 0;
                    for (uint32_t i = 0; i < o.width; ++i)
                        if (o.first[i] < o.first[i + 1]) {
                            uint64_t bottom = y + o.runs[o.first[i]].x;
                            waste += double(bottom - fine.floorBelow(x + i, bottom));
                        }
                    double score = double(y + maxTop) + wasteWeight * waste / o.width;
                    if (score < best.score) best = {y + maxTop, score, x, uint32_t(y), k, true};
                    return;
                }
                if (best.found && best.top <= maxTop) return;
                uint64_t limit = best.found ? best.top - maxTop - 1 : ~0ull >> 2;
                uint64_t y = lowestFit(search, so, x, limit);
                if (y + maxTop < best.top)
                    best = {y + maxTop, double(y + maxTop), x, uint32_t(y), k, true};
            };
            // Every offset on narrow bins; on wide ones a stride, then every offset around the
            // best strided one, which keeps packing linear in the chart count.
            uint32_t positions = (binWidth - o.width) / s + 1;
            uint32_t stride = std::max(1u, positions / kMaxStridedPositions);
            Candidate before = best;
            for (uint32_t x = 0; x < positions; x += stride) tryAt(x);
            if (stride > 1 && best.found &&
                (best.x != before.x || best.orientation != before.orientation || !before.found)) {
                uint32_t centre = best.x;
                uint32_t from = centre >= stride ? centre - stride + 1 : 0;
                uint32_t to = std::min(positions - 1, centre + stride - 1);
                for (uint32_t x = from; x <= to; ++x) tryAt(x);
            }
        }
        if (!best.found) return {};
        const ChartOutline& o = outlines[c][best.orientation];
        uint32_t x = best.x * s;
        uint32_t y = s == 1 ? best.y : uint32_t(lowestFit(fine, o, x, ~0ull >> 2));
        uint32_t maxTop = 0;
        for (uint32_t i = 0; i < o.width; ++i) {
            for (uint32_t k = o.first[i]; k < o.first[i + 1]; ++k) {
                glm::uvec2 run = o.runs[k] + glm::uvec2(y);
                fine.add(x + i, run);
                if (s > 1) coarseOccupancy.add((x + i) / s, run);
                maxTop = std::max(maxTop, o.runs[k].y);
            }
            if (o.first[i] < o.first[i + 1]) right = std::max(right, x + i + 1);
        }
        pack.placements[c] = {x, y, best.orientation};
        top = std::max(top, y + maxTop);
    }
    // Outline column/row i holds content column/row i - gutter, and the outline reaches 2 * gutter
    // past its content's far side: in rect coordinates (bin - gutter) the content ends 2 * gutter
    // before the outline does.
    pack.width = roundUp(std::max(right, 2 * gutter + 1) - 2 * gutter, granularity);
    pack.height = roundUp(std::max(top, 2 * gutter + 1) - 2 * gutter, granularity);
    return pack;
}

} // namespace

uint32_t ChartOutline::occupiedShadels() const {
    uint32_t sum = 0;
    for (const glm::uvec2& run : runs) sum += run.y - run.x;
    return sum;
}

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
    // Per content column, the row ranges of the triangles crossing it.
    std::vector<std::vector<glm::uvec2>> columns(static_cast<size_t>(cw));
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
            columns[size_t(j)].push_back(glm::uvec2(uint32_t(r0), uint32_t(r1) + 1));
        }
    }
    for (std::vector<glm::uvec2>& col : columns) mergeRuns(col);
    // Dilate by the gutter: outline column i sees content columns i - 2g .. i, whose runs
    // [a, b) become [a, b + 2g) in outline rows (shifted up by g, grown by g both ways).
    ChartOutline o;
    o.width = uint32_t(cw) + 2 * gutter;
    o.height = uint32_t(ch) + 2 * gutter;
    o.first.reserve(o.width + 1);
    std::vector<glm::uvec2> merged;
    for (int i = 0; i < int(o.width); ++i) {
        o.first.push_back(uint32_t(o.runs.size()));
        merged.clear();
        for (int j = std::max(0, i - 2 * int(gutter)); j <= std::min(i, cw - 1); ++j)
            for (glm::uvec2 run : columns[size_t(j)])
                merged.push_back(glm::uvec2(run.x, run.y + 2 * gutter));
        mergeRuns(merged);
        o.runs.insert(o.runs.end(), merged.begin(), merged.end());
    }
    o.first.push_back(uint32_t(o.runs.size()));
    return o;
}

OutlinePack packOutlines(const std::vector<std::array<ChartOutline, kOrientations>>& outlines,
                         uint32_t gutter, uint32_t granularity) {
    if (outlines.empty()) return {{}, granularity, granularity};
    double area = 0;
    uint32_t minWidthNeeded = 1;
    std::vector<double> chartArea(outlines.size(), 0.0);
    for (size_t c = 0; c < outlines.size(); ++c) {
        uint32_t narrowest = ~0u;
        for (const ChartOutline& o : outlines[c])
            if (o.width > 0) narrowest = std::min(narrowest, o.width - 2 * gutter);
        minWidthNeeded = std::max(minWidthNeeded, narrowest);
        chartArea[c] = outlines[c][0].occupiedShadels();
        area += chartArea[c];
    }
    // Big charts first, so small ones fill the gaps and holes they leave; ties by index keep the
    // result deterministic. "Big" by occupied area, and for few charts (cheap to pack) also by
    // longest side and by height, each at more bin widths: the best result wins.
    auto sortedBy = [&](auto key) {
        std::vector<uint32_t> order(outlines.size());
        std::iota(order.begin(), order.end(), 0u);
        std::stable_sort(order.begin(), order.end(),
                         [&](uint32_t a, uint32_t b) { return key(a) > key(b); });
        return order;
    };
    double side = std::sqrt(area);
    OutlinePack best;
    double bestScore = 1e300;
    double wasteWeight = 0;
    auto tryWidths = [&](const std::vector<uint32_t>& order, const std::vector<double>& factors) {
        uint32_t lastWidth = 0;
        for (double factor : factors) {
            uint32_t width =
                roundUp(std::max(minWidthNeeded, uint32_t(std::ceil(side * factor))), granularity);
            if (width == lastWidth) continue;
            lastWidth = width;
            OutlinePack pack =
                packAtWidth(outlines, order, width, gutter, granularity, wasteWeight);
            if (pack.width == 0) continue;
            double aspect =
                double(std::max(pack.width, pack.height)) / std::min(pack.width, pack.height);
            double score = double(pack.width) * pack.height * (aspect > 2.0 ? aspect / 2.0 : 1.0);
            if (score < bestScore) bestScore = score, best = std::move(pack);
        }
    };
    tryWidths(sortedBy([&](uint32_t c) { return chartArea[c]; }), {1.0, 1.15, 1.35, 1.6});
    // Outlines already covering most of the rect leave little to win (boxes, planes).
    bool tight = best.width != 0 && area >= kTightOutlineFill * double(best.width) * best.height;
    if (outlines.size() <= kThoroughPackingCharts && !tight) {
        std::vector<double> factors;
        for (double f = 0.9; f < 2.01; f += 0.05) factors.push_back(f);
        tryWidths(sortedBy([&](uint32_t c) { return chartArea[c]; }), factors);
        tryWidths(sortedBy([&](uint32_t c) {
                      return double(std::max(outlines[c][0].width, outlines[c][0].height));
                  }),
                  factors);
        tryWidths(sortedBy([&](uint32_t c) {
                      return double(std::min(outlines[c][0].width, outlines[c][0].height));
                  }),
                  factors);
        if (outlines.size() <= kWasteAwareCharts) {
            // Bottom-left leaves empty pockets under round charts; placing each chart where it
            // sits low *and* leaves little empty space beneath it packs blobs more tightly.
            wasteWeight = kWasteWeight;
            tryWidths(sortedBy([&](uint32_t c) { return chartArea[c]; }), factors);
            tryWidths(sortedBy([&](uint32_t c) {
                          return double(std::max(outlines[c][0].width, outlines[c][0].height));
                      }),
                      factors);
            wasteWeight = 0;
        }
    }
    return best;
}

} // namespace shadel
