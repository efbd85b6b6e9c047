#pragma once
// Distortion of a flattened chart, from the singular values of the linear map surface -> chart on
// every triangle (chart coordinates in metres). Scaling the chart by 1 / maxSigma makes the map
// never magnify: adjacent shadel centres are then >= 1 / density apart on the surface, and
// 1 / sigmaMin of a triangle, relative to that, is its "stretch": the worst spacing between
// adjacent shadel centres in it, in shadels (1 = undistorted, planar projection gives 1/cos tilt).
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace shadel {

struct ChartDistortion {
    double maxSigma = 0;           // largest singular value over the chart
    double minSigma = 1e300;       // smallest singular value over the chart
    double areaOverMinSigma = 0;   // sum of area / sigmaMin over triangles
    double area = 0;               // surface m^2
    uint32_t flippedTriangles = 0; // reversed or collapsed in the chart

    // Worst stretch once normalized by maxSigma (the 1 .. 1/cos bound of bake_validate.h).
    double maxStretch() const { return minSigma > 0 ? maxSigma / minSigma : 1e300; }
    // Area-weighted mean stretch once normalized by maxSigma.
    double meanStretch() const { return area > 0 ? maxSigma * areaOverMinSigma / area : 1.0; }
};

// surface: 3 corners per triangle; chart: the same corners flattened (counter-clockwise when the
// triangle faces its normal). Triangles of zero surface area are skipped.
ChartDistortion measureDistortion(const std::vector<glm::dvec3>& surface,
                                  const std::vector<glm::dvec2>& chart);

} // namespace shadel
