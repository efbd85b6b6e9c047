#include "render/view_distance.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace shadel {
namespace {

using Polygon = std::vector<glm::vec3>;

// Sutherland-Hodgman against one plane (inside: dot(n, p) + d >= 0).
Polygon clip(const Polygon& poly, const glm::vec4& plane) {
    Polygon out;
    for (size_t i = 0; i < poly.size(); ++i) {
        glm::vec3 a = poly[i], b = poly[(i + 1) % poly.size()];
        float da = glm::dot(glm::vec3(plane), a) + plane.w;
        float db = glm::dot(glm::vec3(plane), b) + plane.w;
        if (da >= 0) out.push_back(a);
        if ((da < 0) != (db < 0)) out.push_back(a + (b - a) * (da / (da - db)));
    }
    return out;
}

float pointSegmentDistance(glm::vec3 p, glm::vec3 a, glm::vec3 b) {
    glm::vec3 ab = b - a;
    float len2 = glm::dot(ab, ab);
    float t = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
    return glm::length(p - (a + ab * t));
}

// Distance from p to a convex planar polygon (its interior included).
float pointPolygonDistance(glm::vec3 p, const Polygon& poly) {
    float best = kNotVisible;
    for (size_t i = 0; i < poly.size(); ++i)
        best = std::min(best, pointSegmentDistance(p, poly[i], poly[(i + 1) % poly.size()]));
    if (poly.size() < 3) return best;
    glm::vec3 n(0.0f); // Newell's normal
    for (size_t i = 0; i < poly.size(); ++i) {
        glm::vec3 a = poly[i], b = poly[(i + 1) % poly.size()];
        n += glm::vec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x),
                       (a.x - b.x) * (a.y + b.y));
    }
    if (glm::length(n) <= 1e-20f) return best;
    n = glm::normalize(n);
    float h = glm::dot(p - poly[0], n);
    glm::vec3 q = p - n * h;
    for (size_t i = 0; i < poly.size(); ++i) {
        glm::vec3 a = poly[i], b = poly[(i + 1) % poly.size()];
        if (glm::dot(glm::cross(b - a, q - a), n) < -1e-6f * glm::dot(b - a, b - a)) return best;
    }
    return std::min(best, std::abs(h));
}

// The 6 faces of the hexahedron with corners c[x | y << 1 | z << 2], each in cyclic order.
std::array<Polygon, 6> faces(const std::array<glm::vec3, 8>& c) {
    std::array<Polygon, 6> f;
    for (int axis = 0; axis < 3; ++axis) {
        int b = 1 << ((axis + 1) % 3), d = 1 << ((axis + 2) % 3);
        for (int side = 0; side < 2; ++side) {
            int base = side << axis;
            f[size_t(axis * 2 + side)] = {c[size_t(base)], c[size_t(base | b)],
                                          c[size_t(base | b | d)], c[size_t(base | d)]};
        }
    }
    return f;
}

} // namespace

RunViews runViews(const Camera& camera, CameraPath path, uint32_t frames, const Aabb& sceneBounds,
                  uint32_t width, uint32_t height, uint32_t maxViews) {
    RunViews r;
    frames = std::max(frames, 1u);
    uint32_t count = std::min(frames, std::max(maxViews, 2u));
    for (uint32_t i = 0; i < count; ++i) {
        uint32_t frame = count == frames ? i : uint32_t(uint64_t(i) * (frames - 1) / (count - 1));
        r.views.push_back(
            makeCameraView(cameraOnPath(camera, path, frame, frames, sceneBounds), width, height));
    }
    r.focalPixels = 0.5f * float(height) * std::abs(r.views.front().proj[1][1]);
    return r;
}

float nearestVisibleDistance(const CameraView& view, const Aabb& box) {
    if (!box.valid()) return kNotVisible;
    std::array<glm::vec4, 6> frustum = frustumPlanes(view.proj * view.view);
    // Quick reject: the box is entirely outside one frustum plane.
    for (const glm::vec4& p : frustum) {
        glm::vec3 v{p.x >= 0 ? box.max.x : box.min.x, p.y >= 0 ? box.max.y : box.min.y,
                    p.z >= 0 ? box.max.z : box.min.z};
        if (glm::dot(glm::vec3(p), v) + p.w < 0) return kNotVisible;
    }
    std::array<glm::vec4, 6> boxPlanes = {
        glm::vec4(1, 0, 0, -box.min.x), glm::vec4(-1, 0, 0, box.max.x),
        glm::vec4(0, 1, 0, -box.min.y), glm::vec4(0, -1, 0, box.max.y),
        glm::vec4(0, 0, 1, -box.min.z), glm::vec4(0, 0, -1, box.max.z)};
    std::array<glm::vec3, 8> boxCorners, frustumCorners;
    glm::mat4 inverse = glm::inverse(view.proj * view.view);
    for (int i = 0; i < 8; ++i) {
        boxCorners[size_t(i)] = {i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y,
                                 i & 4 ? box.max.z : box.min.z};
        glm::vec4 w = inverse * glm::vec4(i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f,
                                          i & 4 ? 1.0f : 0.0f, 1.0f);
        frustumCorners[size_t(i)] = glm::vec3(w) / w.w;
    }
    // The boundary of box ∩ frustum: box faces clipped by the frustum, frustum faces by the box
    // (the eye is the frustum's apex, never inside it, so the nearest point is on that boundary).
    float best = kNotVisible;
    for (const Polygon& face : faces(boxCorners)) {
        Polygon p = face;
        for (const glm::vec4& plane : frustum)
            if (!p.empty()) p = clip(p, plane);
        if (!p.empty()) best = std::min(best, pointPolygonDistance(view.position, p));
    }
    for (const Polygon& face : faces(frustumCorners)) {
        Polygon p = face;
        for (const glm::vec4& plane : boxPlanes)
            if (!p.empty()) p = clip(p, plane);
        if (!p.empty()) best = std::min(best, pointPolygonDistance(view.position, p));
    }
    return best == kNotVisible ? best : std::max(best, view.znear);
}

float nearestVisibleDistance(const RunViews& views, const Aabb& box) {
    float best = kNotVisible;
    for (const CameraView& v : views.views) best = std::min(best, nearestVisibleDistance(v, box));
    return best;
}

} // namespace shadel
