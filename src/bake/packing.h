#pragma once
// Packing: places chart rectangles (sizes in whole shadels, gutters included) in a near-square
// rect with a skyline bottom-left packer; each rect may be turned a quarter turn.
#include <cstdint>
#include <vector>

namespace shadel {

struct PackRect {
    uint32_t width = 0, height = 0;
};

struct PackPlacement {
    uint32_t x = 0, y = 0;
    bool turned = false; // placed as height x width
};

struct PackResult {
    std::vector<PackPlacement> placements; // one per input rect, same order
    uint32_t width = 0, height = 0;        // bounding size, each rounded up to `granularity`
};

// Packs into one bin of the given width (height grows as needed).
PackResult packSkyline(const std::vector<PackRect>& rects, uint32_t binWidth, uint32_t granularity);

// Tries several bin widths around sqrt(total area) and keeps the smallest result whose aspect
// ratio stays within 2:1 when possible. Deterministic.
PackResult packNearSquare(const std::vector<PackRect>& rects, uint32_t granularity);

} // namespace shadel
