#pragma once
// Charting: splits a mesh into charts that flatten without overlap and with little distortion,
// and gives every chart vertex a 2-D coordinate in metres. Scale-free: packing decides density.
//
// Charts grow over triangles within a normal cone (developable enough to flatten), are flattened
// by a least-squares conformal map (lscm.h, with an ARAP rescue, arap.h) and accepted when no
// triangle folds, the chart does not overlap itself and its stretch (stretch.h) stays within the
// bound bake_validate.h checks; otherwise they are cut in two and retried. Growth first uses a
// wide cone; a wide chart that does not flatten whole is also regrown with the narrow cone, and
// whichever gives fewer charts is kept. Per-chart density deviation is allowed a loose bound as
// long as the whole mesh's density CV stays below bake_validate.h's, else the mesh is charted
// again with a bound that guarantees it. Small pieces that still fail fall back to planar
// projection, which never folds for triangles facing the projection axis.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace shadel {

enum class ChartKind : uint8_t {
    Conformal,       // least-squares conformal map, scaled never to magnify; coords in metres
    Planar,          // triangles projected on the plane of their mean normal; coords in metres
    DegenerateCells, // zero-area triangles, one unit cell each; coords in shadels, never scaled
};

struct Chart {
    ChartKind kind = ChartKind::Planar;
    uint32_t firstVertex = 0; // baked vertices of a chart are contiguous
    uint32_t vertexCount = 0;
    glm::dvec2 extent{0.0}; // local coords lie in [0, extent]; extent.x >= extent.y
    double surfaceArea = 0; // object-space m^2
    // Shadel spacing on the surface relative to the density (stretch.h): >= 1, area-weighted
    // mean and worst triangle. 1 for DegenerateCells (never sampled).
    double meanStretch = 1, maxStretch = 1;
    // Density relative to the requested one, d = sigmaMax * sigmaMin / maxSigma^2 per triangle
    // (stretch.h): sums of area * d and area * d^2 over the chart, for the mesh's density CV.
    double densitySum = 0, densitySquareSum = 0;
};

struct ChartedMesh {
    std::vector<uint32_t> vertexRemap; // baked vertex -> source vertex
    std::vector<glm::dvec2> local;     // baked vertex -> chart-local 2-D coordinate
    std::vector<uint32_t> indices;     // baked indices, source triangle order
    std::vector<Chart> charts;
    uint32_t degenerateTriangles = 0;
    double surfaceArea = 0;
};

struct ChartingSettings {
    // Planar charts keep every normal within coneDegrees + 10 of the projection axis, so their
    // stretch is at most 1 / cos(coneDegrees + 10); conformal charts meet a tighter stretch bound.
    float coneDegrees = 40.0f;
    // Normal cone of the first (wide) growth, degrees; 0 = coneDegrees + 35, at most 75. Wider
    // cones make fewer, more curved charts (the stretch and density checks still decide what is
    // kept): bake.cpp tries a few when a mesh of few charts packs poorly.
    float wideGrowthDegrees = 0.0f;
};

// Throws InputError if an index is out of range.
ChartedMesh buildCharts(const Mesh& mesh, const ChartingSettings& settings);

} // namespace shadel
