#include "bake/packing.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numeric>

namespace shadel {
namespace {

uint32_t roundUp(uint32_t v, uint32_t granularity) {
    return (v + granularity - 1) / granularity * granularity;
}

// The skyline: contiguous horizontal segments covering [0, binWidth), each at the height of
// the highest rect below it. Bottom-left: each rect goes where its top ends lowest.
class Skyline {
public:
    explicit Skyline(uint32_t width) : width_(width) { segments_.push_back({0, 0, width}); }

    struct Fit {
        size_t segment = 0;
        uint32_t x = 0, y = 0;
        bool found = false;
    };

    Fit find(uint32_t w, uint32_t h) const {
        Fit best;
        uint64_t bestTop = ~0ull;
        for (size_t i = 0; i < segments_.size(); ++i) {
            uint32_t x = segments_[i].x;
            if (x + uint64_t(w) > width_) break;
            uint32_t y = 0;
            for (size_t j = i; j < segments_.size() && segments_[j].x < x + w; ++j)
                y = std::max(y, segments_[j].y);
            uint64_t top = uint64_t(y) + h;
            if (top < bestTop) bestTop = top, best = {i, x, y, true};
        }
        return best;
    }

    void place(const Fit& fit, uint32_t w, uint32_t h) {
        uint32_t right = fit.x + w;
        size_t i = fit.segment;
        segments_.insert(segments_.begin() + std::ptrdiff_t(i), Segment{fit.x, fit.y + h, w});
        size_t j = i + 1;
        while (j < segments_.size() && segments_[j].x < right) {
            Segment& s = segments_[j];
            if (s.x + s.w <= right) {
                segments_.erase(segments_.begin() + std::ptrdiff_t(j));
            } else {
                s.w -= right - s.x;
                s.x = right;
                break;
            }
        }
        // Merge equal-height neighbours so the segment count stays small.
        for (size_t k = (i > 0 ? i - 1 : 0); k + 1 < segments_.size() && k <= i + 1;) {
            if (segments_[k].y == segments_[k + 1].y) {
                segments_[k].w += segments_[k + 1].w;
                segments_.erase(segments_.begin() + std::ptrdiff_t(k + 1));
            } else {
                ++k;
            }
        }
    }

private:
    struct Segment {
        uint32_t x, y, w;
    };
    uint32_t width_;
    std::vector<Segment> segments_;
};

} // namespace

PackResult packSkyline(const std::vector<PackRect>& rects, uint32_t binWidth,
                       uint32_t granularity) {
    std::vector<uint32_t> order(rects.size());
    std::iota(order.begin(), order.end(), 0u);
    // Big rects first; ties by index keep the result deterministic.
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        uint32_t ma = std::max(rects[a].width, rects[a].height);
        uint32_t mb = std::max(rects[b].width, rects[b].height);
        if (ma != mb) return ma > mb;
        return std::min(rects[a].width, rects[a].height) >
               std::min(rects[b].width, rects[b].height);
    });
    Skyline skyline(binWidth);
    PackResult result;
    result.placements.resize(rects.size());
    uint32_t right = 0, top = 0;
    for (uint32_t r : order) {
        uint32_t w = rects[r].width, h = rects[r].height;
        Skyline::Fit upright = skyline.find(w, h);
        Skyline::Fit turned = w != h ? skyline.find(h, w) : Skyline::Fit{};
        bool turn =
            turned.found && (!upright.found || uint64_t(turned.y) + w < uint64_t(upright.y) + h);
        if (!upright.found && !turn) return {}; // does not fit this bin width
        const Skyline::Fit& fit = turn ? turned : upright;
        uint32_t pw = turn ? h : w, ph = turn ? w : h;
        skyline.place(fit, pw, ph);
        result.placements[r] = {fit.x, fit.y, turn};
        right = std::max(right, fit.x + pw);
        top = std::max(top, fit.y + ph);
    }
    result.width = roundUp(std::max(right, 1u), granularity);
    result.height = roundUp(std::max(top, 1u), granularity);
    return result;
}

PackResult packNearSquare(const std::vector<PackRect>& rects, uint32_t granularity) {
    if (rects.empty()) return {{}, granularity, granularity};
    double area = 0;
    uint32_t minSideNeeded = 1;
    for (const PackRect& r : rects) {
        area += double(r.width) * r.height;
        minSideNeeded = std::max(minSideNeeded, std::min(r.width, r.height));
    }
    double side = std::sqrt(area);
    PackResult best;
    double bestScore = 1e300;
    uint32_t lastWidth = 0;
    for (double factor : {0.85, 0.95, 1.0, 1.05, 1.15, 1.3, 1.5, 2.0}) {
        uint32_t width =
            roundUp(std::max(minSideNeeded, uint32_t(std::ceil(side * factor))), granularity);
        if (width == lastWidth) continue;
        lastWidth = width;
        PackResult r = packSkyline(rects, width, granularity);
        if (r.width == 0) continue;
        double aspect = double(std::max(r.width, r.height)) / std::min(r.width, r.height);
        double score = double(r.width) * r.height * (aspect > 2.0 ? aspect / 2.0 : 1.0);
        if (score < bestScore) bestScore = score, best = std::move(r);
    }
    return best;
}

} // namespace shadel
