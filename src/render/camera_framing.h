#pragma once
// Automatic framing and the command line's camera overrides (--from, --look-at, --fov).
#include <optional>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace shadel {

// How much of the limiting image dimension (height or width) the framed geometry spans.
constexpr float kFramingFill = 0.92f;

// A perspective camera looking along `forward` (up +Y) that fits every vertex of the scene's
// instances inside `fill` of the image, centred: for each vertex q (relative to the bounds'
// centre, in the camera's right/up/forward axes x, y, z) the camera offset a along x and
// distance d must satisfy |x - a| <= tanX (z + d), which bounds d from below by
// (max(x - tanX z) - min(x + tanX z)) / 2 tanX with a in the middle; the same for y. Exact and
// linear in the vertex count. Near and far planes enclose the vertices.
Camera frameScene(const Scene& scene, glm::vec3 forward, float yfov, float aspect,
                  float fill = kFramingFill);

// The direction automatic cameras prefer: down and across the scene from +X +Y +Z.
glm::vec3 automaticViewDirection();

// The automatic camera: frameScene from a few directions around the scene (three-quarter views,
// front, sides, back, top), keeping the one whose triangles cover the most of a coarse grid of
// the image (the three-quarter view from +X +Y +Z when it covers 30%, or unless another covers
// 25% more; the elevated views foreshorten tall models, which 16:9 images show small). Flat or
// elongated models are then seen from the side that shows them, not edge-on. Only the sides of
// triangles meant to be seen count (fronts; both of double-sided materials), and a view from
// behind (-Z: glTF assets face +Z) must cover 25% more than one from in front.
Camera frameAutomatically(const Scene& scene, float yfov, float aspect);

struct CameraOverrides {
    std::optional<glm::vec3> from;   // --from: camera position
    std::optional<glm::vec3> lookAt; // --look-at: the point the camera aims at
    float fovDegrees = 0.0f;         // --fov: vertical field of view (0 = the camera's)
};

// The camera a run uses: `name` as findCamera picks it ("auto": automatic framing even when
// the file has cameras), automatic ones refitted for `aspect`, then the overrides applied.
// --from without --look-at aims at the scene's centre; --look-at alone turns the camera in
// place. A moved camera gets near/far planes enclosing the scene; --fov on an orthographic
// camera makes it perspective. Throws InputError naming the flag when --from equals --look-at.
Camera runCamera(const Scene& scene, const std::string& name, const CameraOverrides& overrides,
                 float aspect);

} // namespace shadel
