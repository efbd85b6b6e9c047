#pragma once
// The cameras a run will use (every frame of its camera path) and how near each of them can see a
// box: the ground truth view-driven shadel density is chosen from (see view_density.h).
#include <cstdint>
#include <limits>
#include <vector>

#include "render/camera.h"

namespace shadel {

struct RunViews {
    std::vector<CameraView> views; // unjittered (jitter moves the frustum by < 1 pixel)
    float focalPixels = 0;         // pixels per unit of tan(angle) at the render resolution
};

// Every frame of `path` over `frames` (sampled evenly, first and last included, when there are
// more than `maxViews`) at width x height pixels.
RunViews runViews(const Camera& camera, CameraPath path, uint32_t frames, const Aabb& sceneBounds,
                  uint32_t width, uint32_t height, uint32_t maxViews = 256);

constexpr float kNotVisible = std::numeric_limits<float>::infinity();

// Nearest distance from the eye to any point of `worldBox` inside the view frustum (at least
// znear), or kNotVisible when the box lies outside it. Exact for the box: the nearest point of
// the convex set box ∩ frustum, found on the faces of both clipped by the other.
float nearestVisibleDistance(const CameraView& view, const Aabb& worldBox);
// The minimum over the run's views.
float nearestVisibleDistance(const RunViews& views, const Aabb& worldBox);

} // namespace shadel
