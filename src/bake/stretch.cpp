#include "bake/stretch.h"

#include <algorithm>
#include <cmath>

namespace shadel {

ChartDistortion measureDistortion(const std::vector<glm::dvec3>& surface,
                                  const std::vector<glm::dvec2>& chart) {
    ChartDistortion d;
    for (size_t t = 0; t + 2 < surface.size(); t += 3) {
        glm::dvec3 e1 = surface[t + 1] - surface[t], e2 = surface[t + 2] - surface[t];
        glm::dvec3 normal = glm::cross(e1, e2);
        double doubleArea = glm::length(normal);
        if (!(doubleArea > 0) || !(glm::length(e1) > 0)) continue;
        // The triangle in an orthonormal frame of its plane: (|e1|, 0) and (x2, y2), y2 > 0.
        glm::dvec3 ex = e1 / glm::length(e1), ey = glm::cross(normal / doubleArea, ex);
        double x1 = glm::length(e1), x2 = glm::dot(e2, ex), y2 = glm::dot(e2, ey);
        glm::dvec2 f1 = chart[t + 1] - chart[t], f2 = chart[t + 2] - chart[t];
        // J maps the frame to the chart: J (x1, 0) = f1, J (x2, y2) = f2.
        glm::dvec2 col0 = f1 / x1, col1 = (f2 - col0 * x2) / y2;
        double a = col0.x, b = col1.x, c = col0.y, e = col1.y;
        double det = a * e - b * c;
        double half = 0.5 * (a * a + b * b + c * c + e * e);
        double root = std::sqrt(std::max(0.0, half * half - det * det));
        double sigmaMax = std::sqrt(half + root);
        double sigmaMin = std::sqrt(std::max(0.0, half - root));
        double area = 0.5 * doubleArea;
        if (!(det > 0) || !std::isfinite(det)) {
            ++d.flippedTriangles;
            sigmaMin = 0;
        }
        d.maxSigma = std::max(d.maxSigma, sigmaMax);
        d.minSigma = std::min(d.minSigma, sigmaMin);
        d.areaOverMinSigma += sigmaMin > 0 ? area / sigmaMin : 1e300;
        d.areaScale += area * sigmaMax * sigmaMin;
        d.areaScaleSquared += area * (sigmaMax * sigmaMin) * (sigmaMax * sigmaMin);
        d.area += area;
    }
    if (d.area == 0) d.minSigma = d.maxSigma = 1;
    return d;
}

} // namespace shadel
