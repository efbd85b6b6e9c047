#pragma once
// Shape-aware chart packing. A chart is described by its outline: per column, the runs of rows
// its triangles touch (conservatively), grown by the gutter on every side. Each chart drops to
// the lowest place where none of its runs meets a run already placed, so round or L-shaped
// charts nest into their neighbours' dents and small charts fall into the holes of rings,
// instead of every chart reserving its whole bounding rectangle.
//
// Gutter guarantee (bake.h): outlines are the content dilated by `gutter` in both axes and never
// overlap, so covered shadels of two charts are more than 2 * gutter apart (Chebyshev distance):
// the same separation padded rectangles gave. Outlines may overhang the rect by the gutter (only
// content must lie inside): the renderer clamps taps to the rect, so a chart on the border reads
// its own border shadels, and no other chart can be there.
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace shadel {

// Orientations a chart may be packed in (the caller defines them; see bake.cpp).
constexpr uint32_t kOrientations = 16;

struct ChartOutline {
    uint32_t width = 0, height = 0; // gutters included
    // Column i occupies rows [runs[k].x, runs[k].y) for k in [first[i], first[i + 1]): sorted,
    // disjoint, not touching. A column with no run is empty.
    std::vector<uint32_t> first;
    std::vector<glm::uvec2> runs;

    uint32_t occupiedShadels() const;
};

// Outline of a chart whose triangles (3 corners each, in shadels) lie in [0, content]: covers
// every shadel a triangle overlaps, plus `gutter` shadels around. Column/row i of the outline is
// content column/row i - gutter.
ChartOutline chartOutline(const std::vector<glm::dvec2>& corners, glm::uvec2 content,
                          uint32_t gutter);

// Quarter turns: orientation k maps a point p of a content box w x h to
//   0: p   1: (p.y, w - p.x)   2: (w - p.x, h - p.y)   3: (h - p.y, p.x)
// (rotations only: triangles keep their winding).
glm::dvec2 turnQuarter(glm::dvec2 p, glm::dvec2 content, uint32_t orientation);

struct OutlinePlacement {
    // Rect position of the chart's content corner (0, 0), i.e. of the outline's corner (g, g).
    uint32_t x = 0, y = 0;
    uint32_t orientation = 0; // which of the chart's outlines was placed
};

struct OutlinePack {
    std::vector<OutlinePlacement> placements; // one per chart, same order
    uint32_t width = 0, height = 0;           // each rounded up to `granularity`
};

// outlines[c][k]: chart c in orientation k (outlines of width 0 are not tried; orientation 0
// must be given). Tries a few bin
// widths around the square root of the outlines' area and keeps the smallest near-square
// (<= 2:1 when possible) result. Deterministic.
OutlinePack packOutlines(const std::vector<std::array<ChartOutline, kOrientations>>& outlines,
                         uint32_t gutter, uint32_t granularity);

} // namespace shadel
