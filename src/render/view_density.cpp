#include "render/view_density.h"

#include <algorithm>
#include <cmath>

#include "scene/mesh_split.h"

namespace shadel {
namespace {

float largestScale(const glm::mat4& m) {
    return std::max(
        {glm::length(glm::vec3(m[0])), glm::length(glm::vec3(m[1])), glm::length(glm::vec3(m[2]))});
}

float maxExtent(const Aabb& b) {
    glm::vec3 e = b.extent();
    return std::max({e.x, e.y, e.z});
}

float pow2Ceil(float v) {
    return std::exp2(std::ceil(std::log2(v)));
}

double meshArea(const Mesh& mesh) {
    double a = 0;
    for (size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
        glm::vec3 p0 = mesh.vertices[mesh.indices[i]].position;
        glm::vec3 p1 = mesh.vertices[mesh.indices[i + 1]].position;
        glm::vec3 p2 = mesh.vertices[mesh.indices[i + 2]].position;
        a += 0.5 * double(glm::length(glm::cross(p1 - p0, p2 - p0)));
    }
    return a;
}

// Whether a mesh part (its object-space box) is small enough for the distance one instance sees
// it from: kept whole unless it is larger than its nearest distance and would be big on the sheet.
// Monotone: a sub-box of a box that passes passes too (smaller, and no nearer).
bool wholeForInstance(const Aabb& box, const Instance& inst, const RunViews& views,
                      const ViewDensityOptions& o) {
    Aabb world = transformAabb(box, inst.transform);
    float d = nearestVisibleDistance(views, world);
    if (d == kNotVisible) return true;
    float e = maxExtent(world);
    return !(e > o.chunkPerDistance * d &&
             e * o.safety * views.focalPixels / d > o.minChunkShadels);
}

// Splits the meshes that are large for the distances they are seen from. Only the instances
// that need it are split (one instance per chunk, same transform, in place of the original);
// the other instances of the mesh keep it whole. A city of a million buildings sharing three
// meshes, of which a few stand next to the camera, gets a few hundred chunk instances, not
// the million times the chunk count. Since the test is monotone, deciding the chunks over the
// instances that need splitting gives the chunks a decision over all instances would give.
Scene chunkScene(const Scene& scene, const RunViews& views, const ViewDensityOptions& o,
                 uint32_t& meshesSplit, uint32_t& chunksMade) {
    Scene out = scene;
    out.meshes.clear();
    out.instances.clear();
    // Per mesh, the instances for which the whole mesh is too large (they take the chunks).
    std::vector<std::vector<uint32_t>> splitFor(scene.meshes.size());
    std::vector<uint32_t> instanceCount(scene.meshes.size(), 0);
    std::vector<uint8_t> takesChunks(scene.instances.size(), 0);
    for (uint32_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        if (inst.mesh >= scene.meshes.size()) continue;
        ++instanceCount[inst.mesh];
        const Mesh& mesh = scene.meshes[inst.mesh];
        float extent = mesh.bounds.valid() ? maxExtent(mesh.bounds) : 0.0f;
        if (!(extent > 0) || !std::isfinite(extent)) continue;
        if (!wholeForInstance(mesh.bounds, inst, views, o)) {
            splitFor[inst.mesh].push_back(i);
            takesChunks[i] = 1;
        }
    }
    std::vector<std::vector<uint32_t>> chunkMeshes(scene.meshes.size());
    std::vector<uint32_t> wholeMesh(scene.meshes.size(), ~0u);
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        // The whole mesh stays for the instances that do not take chunks (and for none at all:
        // meshes keep their place in the list whether or not an instance uses them).
        bool keepsWhole = splitFor[m].empty() || splitFor[m].size() < instanceCount[m];
        if (keepsWhole) {
            wholeMesh[m] = uint32_t(out.meshes.size());
            out.meshes.push_back(mesh);
        }
        if (splitFor[m].empty()) continue;
        float cell = pow2Ceil(maxExtent(mesh.bounds) / float(std::max(o.maxCellsPerAxis, 1u)));
        auto wholeNode = [&](const Aabb& box) {
            for (uint32_t i : splitFor[m])
                if (!wholeForInstance(box, scene.instances[i], views, o)) return false;
            return true;
        };
        std::vector<Mesh> parts = splitMeshOnGrid(mesh, cell, wholeNode);
        if (parts.size() == 1 && keepsWhole) { // a single cell: the whole mesh it is
            chunkMeshes[m].push_back(wholeMesh[m]);
            continue;
        }
        if (parts.size() > 1) ++meshesSplit, chunksMade += uint32_t(parts.size());
        for (Mesh& part : parts) {
            chunkMeshes[m].push_back(uint32_t(out.meshes.size()));
            out.meshes.push_back(std::move(part));
        }
    }
    for (uint32_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        if (inst.mesh >= scene.meshes.size()) {
            out.instances.push_back(inst);
            continue;
        }
        if (!takesChunks[i]) {
            Instance whole = inst;
            whole.mesh = wholeMesh[inst.mesh];
            out.instances.push_back(std::move(whole));
            continue;
        }
        const std::vector<uint32_t>& parts = chunkMeshes[inst.mesh];
        for (size_t k = 0; k < parts.size(); ++k) {
            Instance chunk = inst;
            chunk.mesh = parts[k];
            if (parts.size() > 1) chunk.name += " chunk " + std::to_string(k);
            out.instances.push_back(std::move(chunk));
        }
    }
    return out;
}

} // namespace

ViewDensity viewDrivenDensity(const Scene& scene, const RunViews& views,
                              const ViewDensityOptions& o) {
    ViewDensity r;
    r.scene = o.chunks ? chunkScene(scene, views, o, r.meshesSplit, r.chunksMade) : scene;
    const Scene& s = r.scene;
    size_t meshCount = s.meshes.size();
    std::vector<float> needed(meshCount, 0.0f), scale(meshCount, 0.0f);
    for (const Instance& inst : s.instances) {
        if (inst.mesh >= meshCount) continue;
        float k = largestScale(inst.transform);
        if (!(k > 0) || !std::isfinite(k)) continue;
        scale[inst.mesh] = std::max(scale[inst.mesh], k);
        float d = nearestVisibleDistance(views,
                                         transformAabb(s.meshes[inst.mesh].bounds, inst.transform));
        if (d == kNotVisible) continue;
        needed[inst.mesh] = std::max(needed[inst.mesh], o.safety * views.focalPixels / d * k);
    }
    const float steps = std::max(o.stepsPerOctave, 1.0f);
    auto quantize = [&](float v, bool up) {
        float q = std::log2(v) * steps;
        return std::exp2((up ? std::ceil(q - 1e-4f) : std::floor(q + 1e-4f)) / steps);
    };
    r.meshDensity.assign(meshCount, 0.0f);
    std::vector<double> area(meshCount);
    double total = 0;
    for (size_t m = 0; m < meshCount; ++m) {
        const Mesh& mesh = s.meshes[m];
        area[m] = meshArea(mesh);
        float extent = mesh.bounds.valid() ? std::max(maxExtent(mesh.bounds), 1e-6f) : 1.0f;
        if (needed[m] > 0 && std::isfinite(needed[m])) {
            r.meshDensity[m] = quantize(needed[m], true);
        } else {
            r.meshDensity[m] = quantize(8.0f / extent, true); // unseen: a minimal rect
            r.meshesUnseen += scale[m] > 0;
        }
        total += area[m] * double(r.meshDensity[m]) * double(r.meshDensity[m]);
    }
    if (total > o.budget && total > 0) {
        r.budgetScale = std::sqrt(o.budget / total);
        total = 0;
        for (size_t m = 0; m < meshCount; ++m) {
            r.meshDensity[m] = quantize(r.meshDensity[m] * float(r.budgetScale), false);
            total += area[m] * double(r.meshDensity[m]) * double(r.meshDensity[m]);
        }
    }
    r.mip0Shadels = total;
    r.minDensityWorld = 1e30f;
    for (size_t m = 0; m < meshCount; ++m) {
        if (!(needed[m] > 0) || !(scale[m] > 0)) continue;
        float world = r.meshDensity[m] / scale[m];
        r.minDensityWorld = std::min(r.minDensityWorld, world);
        r.maxDensityWorld = std::max(r.maxDensityWorld, world);
    }
    if (r.maxDensityWorld == 0) r.minDensityWorld = 0;
    return r;
}

} // namespace shadel
