#include "render/camera_framing.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <vector>

#include "core/error.h"
#include "core/log.h"
#include "render/camera.h"

namespace shadel {

namespace {

glm::vec3 upFor(glm::vec3 forward) {
    glm::vec3 up(0, 1, 0);
    if (std::abs(glm::dot(up, forward)) > 0.999f) up = {0, 0, -1};
    return glm::normalize(up - forward * glm::dot(up, forward));
}

// Calls f(world position) for every vertex of every instance.
template <typename F>
void forEachVertex(const Scene& scene, F&& f) {
    for (const Instance& inst : scene.instances) {
        if (inst.mesh >= scene.meshes.size()) continue;
        for (const Vertex& v : scene.meshes[inst.mesh].vertices)
            f(glm::vec3(inst.transform * glm::vec4(v.position, 1.0f)));
    }
}

// Near and far planes enclosing the scene's bounds seen from `position` along `forward`.
void fitDepthRange(Camera& c, const Aabb& bounds) {
    float nearest = 1e30f, farthest = -1e30f;
    for (int i = 0; i < 8; ++i) {
        glm::vec3 corner{i & 1 ? bounds.max.x : bounds.min.x, i & 2 ? bounds.max.y : bounds.min.y,
                         i & 4 ? bounds.max.z : bounds.min.z};
        float z = glm::dot(corner - c.position, c.forward);
        nearest = std::min(nearest, z), farthest = std::max(farthest, z);
    }
    float radius = std::max(0.5f * glm::length(bounds.extent()), 1e-3f);
    // The camera may stand inside the bounds: the near plane then stays a small fraction of the
    // scene's size (reversed Z keeps the precision).
    c.znear = std::max(nearest * 0.5f, radius * 1e-3f);
    c.zfar = std::max(farthest * 1.05f + radius * 0.01f, c.znear * 2.0f);
}

// Candidate directions (from the scene toward the camera) for automatic framing; the first is
// the preferred three-quarter view.
constexpr glm::vec3 kCandidateSides[] = {
    {1.0f, 0.6f, 1.0f},  {-1.0f, 0.6f, 1.0f}, {0.0f, 0.3f, 1.0f},  {1.0f, 0.3f, 0.0f},
    {-1.0f, 0.3f, 0.0f}, {0.0f, 0.3f, -1.0f}, {1.0f, 0.6f, -1.0f}, {-1.0f, 0.6f, -1.0f},
    {0.0f, 1.0f, 1.0f},  {1.0f, 1.0f, 0.0f},  {0.0f, 1.0f, -1.0f}, {-1.0f, 1.0f, 0.0f},
    {0.2f, 1.0f, 0.3f},
};
// The preferred direction is kept when it covers at least this much of the image, or when no
// other covers 25% more.
constexpr float kPreferredCoverage = 0.3f;
constexpr float kPreferredBonus = 1.25f;

// Cells of a coarse grid marked covered, each at most once: per row, a link from every cell to
// the next cell that is still uncovered (path-compressed), so marking a span costs the cells it
// newly covers plus a near-constant, never the span's length again.
class CoverageGrid {
public:
    CoverageGrid(int width, int height)
        : width_(width), height_(height), next_(size_t(width + 1) * size_t(height)) {
        for (int y = 0; y < height; ++y)
            for (int x = 0; x <= width; ++x) next_[index(x, y)] = x;
    }
    // Marks cells x0..x1 of row y.
    void mark(int y, int x0, int x1) {
        for (int x = find(x0, y); x <= x1; x = find(x, y)) {
            next_[index(x, y)] = x + 1;
            ++covered_;
        }
    }
    float fraction() const { return float(covered_) / float(size_t(width_) * size_t(height_)); }

private:
    size_t index(int x, int y) const { return size_t(y) * size_t(width_ + 1) + size_t(x); }
    int find(int x, int y) {
        int root = x;
        while (next_[index(root, y)] != root) root = next_[index(root, y)];
        while (next_[index(x, y)] != root) { // path compression
            int up = next_[index(x, y)];
            next_[index(x, y)] = root;
            x = up;
        }
        return root;
    }
    int width_, height_;
    std::vector<int> next_; // per row: width + 1 links (the last, a sentinel, points at itself)
    size_t covered_ = 0;
};

// Marks the cells whose centres lie inside triangle a, b, d (grid units), row by row: per row
// the triangle's cross-section at the cell centres' height is one interval.
void markTriangle(CoverageGrid& grid, int gridW, int gridH, glm::vec2 a, glm::vec2 b, glm::vec2 d) {
    int y0 = std::max(0, int(std::ceil(std::min({a.y, b.y, d.y}) - 0.5f)));
    int y1 = std::min(gridH - 1, int(std::floor(std::max({a.y, b.y, d.y}) - 0.5f)));
    for (int y = y0; y <= y1; ++y) {
        float py = float(y) + 0.5f;
        float left = INFINITY, right = -INFINITY;
        for (auto [u, v] : {std::pair{a, b}, std::pair{b, d}, std::pair{d, a}}) {
            if ((u.y - py) * (v.y - py) > 0.0f) continue; // the edge does not reach this row
            if (u.y == v.y) {                             // along the row
                left = std::min({left, u.x, v.x}), right = std::max({right, u.x, v.x});
                continue;
            }
            float x = u.x + (py - u.y) / (v.y - u.y) * (v.x - u.x);
            left = std::min(left, x), right = std::max(right, x);
        }
        int x0 = std::max(0, int(std::ceil(left - 0.5f)));
        int x1 = std::min(gridW - 1, int(std::floor(right - 0.5f)));
        if (x0 <= x1) grid.mark(y, x0, x1);
    }
}

// Triangles the estimate looks at, at most: a larger scene is sampled at a fixed stride (the
// same for every candidate view, so the comparison stays fair).
constexpr size_t kMaxEstimateTriangles = 1u << 18;

// Fraction of the image the scene's triangles cover seen by `c`, on a coarse grid (cell
// centres inside a triangle). Only the sides meant to be seen count: a triangle's front
// (counter-clockwise in glTF, the other way under a mirroring transform), or both sides of a
// double-sided material; so a view of a model's back (a row of backdrops hiding the samples in
// front of them, ClearCoatTest.gltf) loses to the view of its front. The cost is bounded by the
// grid, not by triangles x cells: at most kMaxEstimateTriangles triangles, each costing its
// rows, and every cell is marked once (a million overlapping screen-filling triangles cost what
// their rows cost).
float estimatedCoverage(const Scene& scene, const Camera& c, float aspect) {
    constexpr int kGridH = 48;
    const int gridW = std::clamp(int(std::lround(kGridH * aspect)), 1, 16 * kGridH);
    CameraView view = makeCameraView(c, uint32_t(gridW), uint32_t(kGridH));
    glm::mat4 viewProj = view.proj * view.view;
    CoverageGrid grid(gridW, kGridH);
    const size_t stride = std::max<size_t>(1, scene.triangleCount() / kMaxEstimateTriangles + 1);
    size_t triangle = 0; // across the scene, for the stride
    std::vector<glm::vec3> projected, world;
    for (const Instance& inst : scene.instances) {
        if (inst.mesh >= scene.meshes.size()) continue;
        const Mesh& mesh = scene.meshes[inst.mesh];
        const size_t triangles = mesh.indices.size() / 3;
        // The first triangle of this instance the stride lands on.
        size_t first = (stride - triangle % stride) % stride;
        triangle += triangles;
        if (first >= triangles) continue;
        bool doubleSided =
            mesh.material < scene.materials.size() && scene.materials[mesh.material].doubleSided;
        float facing = glm::determinant(glm::mat3(inst.transform)) < 0.0f ? -1.0f : 1.0f;
        glm::mat4 m = viewProj * inst.transform;
        projected.resize(mesh.vertices.size());
        world.resize(mesh.vertices.size());
        for (size_t i = 0; i < mesh.vertices.size(); ++i) {
            world[i] = glm::vec3(inst.transform * glm::vec4(mesh.vertices[i].position, 1.0f));
            glm::vec4 clip = m * glm::vec4(mesh.vertices[i].position, 1.0f);
            projected[i] =
                clip.w > 1e-12f
                    ? glm::vec3((glm::vec2(clip) / clip.w * 0.5f + 0.5f) * glm::vec2(gridW, kGridH),
                                1.0f)
                    : glm::vec3(0.0f); // behind: z = 0 marks it
        }
        for (size_t t = first * 3; t + 2 < mesh.indices.size(); t += 3 * stride) {
            glm::vec3 a = projected[mesh.indices[t]], b = projected[mesh.indices[t + 1]],
                      d = projected[mesh.indices[t + 2]];
            if (a.z == 0.0f || b.z == 0.0f || d.z == 0.0f) continue;
            if (!doubleSided) {
                const glm::vec3 &wa = world[mesh.indices[t]], &wb = world[mesh.indices[t + 1]],
                                &wd = world[mesh.indices[t + 2]];
                if (facing * glm::dot(glm::cross(wb - wa, wd - wa), c.position - wa) <= 0.0f)
                    continue; // its back faces the camera
            }
            float area = (b.x - a.x) * (d.y - a.y) - (b.y - a.y) * (d.x - a.x);
            if (area == 0.0f || !std::isfinite(area)) continue;
            markTriangle(grid, gridW, kGridH, glm::vec2(a), glm::vec2(b), glm::vec2(d));
        }
    }
    return grid.fraction();
}

} // namespace

glm::vec3 automaticViewDirection() {
    return -glm::normalize(glm::vec3(1.0f, 0.6f, 1.0f));
}

Camera frameScene(const Scene& scene, glm::vec3 forward, float yfov, float aspect, float fill) {
    Camera c;
    c.name = "auto";
    c.automatic = true;
    c.yfov = yfov;
    c.forward = glm::normalize(forward);
    c.up = upFor(c.forward);
    glm::vec3 right = glm::cross(c.forward, c.up);
    Aabb bounds = scene.worldBounds();
    glm::vec3 centre = bounds.valid() ? bounds.center() : glm::vec3(0.0f);
    float tanY = std::tan(0.5f * yfov) * fill, tanX = tanY * aspect;
    // Over the vertices: max(x - tanX z), min(x + tanX z), the same for y, and the depth range.
    float hiX = -1e30f, loX = 1e30f, hiY = -1e30f, loY = 1e30f, minZ = 1e30f;
    bool any = false;
    forEachVertex(scene, [&](glm::vec3 p) {
        glm::vec3 q = p - centre;
        float x = glm::dot(q, right), y = glm::dot(q, c.up), z = glm::dot(q, c.forward);
        hiX = std::max(hiX, x - tanX * z), loX = std::min(loX, x + tanX * z);
        hiY = std::max(hiY, y - tanY * z), loY = std::min(loY, y + tanY * z);
        minZ = std::min(minZ, z);
        any = true;
    });
    float radius = bounds.valid() ? std::max(0.5f * glm::length(bounds.extent()), 1e-3f) : 1.0f;
    if (!any) hiX = hiY = radius, loX = loY = -radius, minZ = -radius;
    float distance = std::max((hiX - loX) / (2.0f * tanX), (hiY - loY) / (2.0f * tanY));
    // Every vertex in front of the camera, however flat the scene is seen.
    distance = std::max(distance, -minZ + radius * 0.05f);
    float offsetX = 0.5f * (hiX + loX), offsetY = 0.5f * (hiY + loY);
    c.position = centre + right * offsetX + c.up * offsetY - c.forward * distance;
    fitDepthRange(c, bounds);
    return c;
}

Camera frameAutomatically(const Scene& scene, float yfov, float aspect) {
    Camera preferred = frameScene(scene, -glm::normalize(kCandidateSides[0]), yfov, aspect);
    float preferredCoverage = estimatedCoverage(scene, preferred, aspect);
    if (preferredCoverage >= kPreferredCoverage) return preferred;
    Camera best = preferred;
    float bestScore = preferredCoverage * kPreferredBonus;
    for (size_t i = 1; i < std::size(kCandidateSides); ++i) {
        Camera c = frameScene(scene, -glm::normalize(kCandidateSides[i]), yfov, aspect);
        float coverage = estimatedCoverage(scene, c, aspect);
        // glTF: "the front of an asset faces +Z". A view from behind must cover 25% more than
        // the others: a closed model covers as much from its back (ClearCoatTest.gltf's slabs
        // of backdrops hide its samples from -Z, and from above and behind covered 0.40 of the
        // image against 0.36 from above and in front).
        float score = kCandidateSides[i].z < 0.0f ? coverage / kPreferredBonus : coverage;
        if (score > bestScore) best = c, bestScore = score;
    }
    return best;
}

Camera runCamera(const Scene& scene, const std::string& name, const CameraOverrides& o,
                 float aspect) {
    Camera c;
    bool named = false;
    for (const Camera& sc : scene.cameras) named |= sc.name == name;
    if (name == "auto" && !named) {
        c.automatic = true;
        c.forward = automaticViewDirection();
    } else {
        c = findCamera(scene, name);
    }
    float fov = o.fovDegrees > 0.0f ? glm::radians(o.fovDegrees) : c.yfov;
    if (o.fovDegrees > 0.0f) c.orthoHalfHeight = 0.0f;
    if (c.automatic) {
        c = frameAutomatically(scene, fov, aspect);
        if (!name.empty()) c.name = name;
    }
    c.yfov = fov;
    if (!o.from && !o.lookAt) return c;
    Aabb bounds = scene.worldBounds();
    glm::vec3 position = o.from.value_or(c.position);
    glm::vec3 target = o.lookAt         ? *o.lookAt
                       : bounds.valid() ? bounds.center()
                                        : position + c.forward;
    glm::vec3 dir = target - position;
    float length = glm::length(dir);
    if (!(length > 1e-6f * std::max(1.0f, glm::length(position))))
        throw InputError(format("--look-at %g,%g,%g: the same point as the camera position",
                                target.x, target.y, target.z));
    c.position = position;
    c.forward = dir / length;
    c.up = upFor(c.forward);
    c.automatic = false;
    if (bounds.valid()) fitDepthRange(c, bounds);
    return c;
}

} // namespace shadel
