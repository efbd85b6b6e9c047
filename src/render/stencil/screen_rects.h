#pragma once
// The screen rectangles a stencil-culled effect draws over (render/stencil): the conservative
// pixel rect of each of its instances' world boxes, and a set of disjoint rects covering their
// union. Disjoint, because the effects read and write the scene colour in place: a pixel two
// rects covered would get the effect twice.
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace shadel {

// Pixels [x0, x1) x [y0, y1); empty when x1 <= x0 or y1 <= y0.
struct PixelRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    bool empty() const { return x1 <= x0 || y1 <= y0; }
    bool operator==(const PixelRect&) const = default;
};

// Every pixel a primitive inside the box [lo, hi] can cover in a `width` x `height` target,
// grown by `margin` pixels and clamped to the target: empty when the box is off-screen or
// wholly behind the camera, the whole target when it straddles the camera plane.
PixelRect projectedBoxRect(const glm::mat4& viewProj, glm::vec3 lo, glm::vec3 hi, int width,
                           int height, int margin);

// Disjoint rects whose union is the union of `rects` (empty ones ignored): horizontal bands
// between the rects' distinct y edges, each band's merged x spans, a span continued downwards
// while the next band has the same span.
std::vector<PixelRect> disjointCover(std::span<const PixelRect> rects);

} // namespace shadel
