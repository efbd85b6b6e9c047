#pragma once
// Independent checks of a bake's invariants, computed from the BakedMesh alone (charts are
// re-derived as connected regions of the baked mesh in UV space). Used by the tests; cheap enough
// for a `shadel bake --check`.
#include <cstdint>
#include <string>
#include <vector>

#include "bake/bake.h"

namespace shadel {

struct BakeValidation {
    std::string structureError;        // empty if sizes, ranges and MIP count are consistent
    uint32_t chartComponents = 0;      // connected components of the baked mesh in UV space
    uint64_t crossChartShadels = 0;    // MIP-0 shadel centres covered by two different charts
    uint64_t doubleCoveredShadels = 0; // covered by two triangles, same chart or not
    uint32_t unownedTriangles = 0;     // triangles with no MIP-0 ID shadel
    // Per MIP level, over bilinear taps at points inside visible (non-zero area) triangles
    // (around every covered shadel centre): reads of empty shadels, and of shadels that belong
    // to a different chart ("foreign").
    std::vector<uint64_t> emptyReads, foreignReads;
    // Shadels per m^2 over non-degenerate triangles, area-weighted.
    double densityMean = 0, densityCv = 0;
    // For MIP-0 shadels whose centre lies inside their triangle, the distance between the
    // position rebuilt with the float shader math (shadel_bary.h) and the exact surface point
    // mapped to that shadel centre, in shadels (world distance * shadelsPerMetre).
    double maxReconstructionError = 0;
    // kMaxReconstructionError plus 4 float ulps of the largest coordinate, in shadels.
    double reconstructionTolerance = 0;
    uint64_t reconstructedShadels = 0;
    // World distance between horizontally adjacent shadel centres inside one triangle, in
    // shadels: 1 for a distortion-free chart; planar projection stretches by 1/cos(tilt).
    double minNeighbourSpacing = 0, maxNeighbourSpacing = 0;
    uint64_t spacingPairs = 0;
};

BakeValidation validateBake(const Mesh& mesh, const BakedMesh& baked);

// The bounds a good bake meets, checked against a validation; "" or the first violation.
//  - structure consistent; no shadel centre covered twice (across charts or within one);
//  - every triangle owns >= 1 MIP-0 ID shadel;
//  - no bilinear tap inside a visible triangle reads an empty shadel, at any MIP level;
//  - no such tap reads another chart's shadel at levels k with 2^k <= gutterShadels;
//  - density coefficient of variation <= kMaxDensityCv;
//  - reconstruction error <= kMaxReconstructionError shadels (+ 4 float ulps of the largest
//    coordinate: float positions bound any float reconstruction) inside their triangle;
//  - adjacent shadel centres are 1 .. 1/cos(cone + 10 deg) shadels apart on the surface (planar
//    projection only ever shortens lengths, by at most the tilt the charting allows).
constexpr double kMaxDensityCv = 0.2;
constexpr double kMaxReconstructionError = 0.01;
std::string bakeViolation(const BakeValidation& validation, const BakeSettings& settings);

} // namespace shadel
