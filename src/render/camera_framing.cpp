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

// Fraction of the image the scene's triangles cover seen by `c`, on a coarse grid (cell
// centres inside a triangle). Only the sides meant to be seen count: a triangle's front
// (counter-clockwise in glTF, the other way under a mirroring transform), or both sides of a
// double-sided material; so a view of a model's back (a row of backdrops hiding the samples in
// front of them, ClearCoatTest.gltf) loses to the view of its front. Linear in the triangles
// plus the cells they cover.
float estimatedCoverage(const Scene& scene, const Camera& c, float aspect) {
    constexpr int kGridH = 48;
    const int gridW = std::clamp(int(std::lround(kGridH * aspect)), 1, 16 * kGridH);
    CameraView view = makeCameraView(c, uint32_t(gridW), uint32_t(kGridH));
    glm::mat4 viewProj = view.proj * view.view;
    std::vector<uint8_t> grid(size_t(gridW) * kGridH, 0);
    std::vector<glm::vec3> projected, world;
    for (const Instance& inst : scene.instances) {
        if (inst.mesh >= scene.meshes.size()) continue;
        const Mesh& mesh = scene.meshes[inst.mesh];
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
        for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
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
            if (area == 0.0f) continue;
            int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, d.x}))));
            int x1 = std::min(gridW - 1, int(std::ceil(std::max({a.x, b.x, d.x}))));
            int y0 = std::max(0, int(std::floor(std::min({a.y, b.y, d.y}))));
            int y1 = std::min(kGridH - 1, int(std::ceil(std::max({a.y, b.y, d.y}))));
            for (int y = y0; y <= y1; ++y) {
                for (int x = x0; x <= x1; ++x) {
                    glm::vec2 p(float(x) + 0.5f, float(y) + 0.5f);
                    auto edge = [&](glm::vec3 u, glm::vec3 v) {
                        return ((v.x - u.x) * (p.y - u.y) - (v.y - u.y) * (p.x - u.x)) * area;
                    };
                    if (edge(a, b) >= 0.0f && edge(b, d) >= 0.0f && edge(d, a) >= 0.0f)
                        grid[size_t(y) * size_t(gridW) + size_t(x)] = 1;
                }
            }
        }
    }
    size_t covered = 0;
    for (uint8_t g : grid) covered += g;
    return float(covered) / float(grid.size());
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
