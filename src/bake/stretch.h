#pragma once
// Distortion of a flattened chart, from the singular values of the linear map surface -> chart on
// every triangle (chart coordinates in metres). Scaling the chart by 1 / maxSigma makes the map
// never magnify: adjacent shadel centres are then >= 1 / density apart on the surface, and
// 1 / sigmaMin of a triangle, relative to that, is its "stretch": the worst spacing between
// adjacent shadel centres in it, in shadels (1 = undistorted, planar projection gives 1/cos tilt).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace shadel {

struct ChartDistortion {
    double maxSigma = 0;           // largest singular value over the chart
    double minSigma = 1e300;       // smallest singular value over the chart
    double areaOverMinSigma = 0;   // sum of area / sigmaMin over triangles
    double areaScale = 0;          // sum of area * sigmaMax * sigmaMin (area scale factor)
    double areaScaleSquared = 0;   // sum of area * (sigmaMax * sigmaMin)^2
    double area = 0;               // surface m^2
    uint32_t flippedTriangles = 0; // reversed or collapsed in the chart

    // Worst stretch once normalized by maxSigma (the 1 .. 1/cos bound of bake_validate.h).
    double maxStretch() const { return minSigma > 0 ? maxSigma / minSigma : 1e300; }
    // Area-weighted mean stretch once normalized by maxSigma.
    double meanStretch() const { return area > 0 ? maxSigma * areaOverMinSigma / area : 1.0; }
    // Once normalized by maxSigma, the density relative to the requested one is d = sigmaMax *
    // sigmaMin / maxSigma^2 <= 1 per triangle; this is the area-weighted RMS of d - 1. If every
    // chart of a mesh keeps it <= delta, the mesh's density CV is <= delta / (1 - delta): its
    // variance is at most the mean square distance to 1, and its mean is >= 1 - delta.
    double densityDeviation() const {
        if (!(area > 0) || !(maxSigma > 0)) return 0;
        double m2 = maxSigma * maxSigma;
        double mean = areaScale / (area * m2), meanSquare = areaScaleSquared / (area * m2 * m2);
        return std::sqrt(std::max(0.0, meanSquare - 2 * mean + 1));
    }
};

// surface: 3 corners per triangle; chart: the same corners flattened (counter-clockwise when the
// triangle faces its normal). Triangles of zero surface area are skipped.
ChartDistortion measureDistortion(const std::vector<glm::dvec3>& surface,
                                  const std::vector<glm::dvec2>& chart);

} // namespace shadel
