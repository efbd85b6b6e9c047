#pragma once
// Least-squares conformal maps (Lévy, Petitjean, Ray, Maillot 2002): flattens one connected
// triangle patch so every triangle keeps its angles as well as possible in the least-squares
// sense. Two vertices are pinned (the patch's approximate diameter, at their 3-D distance), so the
// result is unique and roughly metric; the caller normalizes the scale (see stretch.h).
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace shadel {

// positions: the patch's vertices (seam duplicates already welded into one); triangles: three
// indices per triangle into positions, none of zero area. Writes one 2-D coordinate per vertex.
// Returns false if the sparse solve fails or gives non-finite coordinates. The map may still fold
// (a patch far from a disk, or very curved): callers check triangle orientation and overlap.
bool lscmFlatten(const std::vector<glm::dvec3>& positions, const std::vector<uint32_t>& triangles,
                 std::vector<glm::dvec2>& uv);

} // namespace shadel
