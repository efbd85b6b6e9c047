#pragma once
// As-rigid-as-possible flattening (Liu, Zhang, Xu, Gotsman, Gortler 2008, "ARAP" local/global):
// refines a fold-free flattening (lscm.h) towards one where every triangle is only rotated. A
// conformal map keeps angles but lets the scale drift across a curved chart; ARAP spreads the
// unavoidable distortion as mild anisotropy instead, which keeps the shadel density much more
// uniform, so curved charts can stay larger.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace shadel {

// positions / triangles as for lscmFlatten; uv holds the starting flattening (orientation as the
// triangles' own frames: counter-clockwise) and receives the result. Returns false if the solve
// fails (uv is then unchanged). The result may fold: callers check, as for LSCM.
bool arapRefine(const std::vector<glm::dvec3>& positions, const std::vector<uint32_t>& triangles,
                std::vector<glm::dvec2>& uv, int iterations);

} // namespace shadel
