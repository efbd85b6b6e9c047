#include "render/culling/mesh_lods.h"

#include <algorithm>

#include <meshoptimizer.h>

namespace shadel {

namespace {
// Level k aims at LOD 0's index count / 2^k under a relative error bound that grows 4x a level
// (meshoptimizer's error is relative to the mesh's extent): whichever is reached first stops it.
constexpr float kFirstLevelError = 2e-3f;
constexpr float kMaxRelativeError = 0.25f;
// A level that keeps more than this share of the previous one is not worth a draw.
constexpr float kMinReduction = 0.8f;
// Point-triangle pairs one level's deviation measurement may test; larger meshes sample LOD 0's
// vertices with a stride (the measured error then underestimates by at most the sampling).
constexpr double kMaxDeviationPairs = 3e7;
// Vertex cache optimization and simplification cost about triangles x valence: a vertex shared
// by more triangles than this (a fan of thousands, a strip of overlapping copies) leaves the
// mesh as authored, with LOD 0 only, so the upload stays linear in the input.
constexpr uint32_t kMaxOptimizedValence = 512;

uint32_t maxValence(const std::vector<uint32_t>& indices, size_t vertexCount) {
    std::vector<uint32_t> valence(vertexCount, 0);
    uint32_t most = 0;
    for (uint32_t i : indices)
        if (i < vertexCount) most = std::max(most, ++valence[i]);
    return most;
}

float pointTriangleDistance(glm::vec3 p, glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    // Ericson, Real-Time Collision Detection 5.1.5: the closest point by Voronoi region.
    glm::vec3 ab = b - a, ac = c - a, ap = p - a;
    float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return glm::length(ap);
    glm::vec3 bp = p - b;
    float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return glm::length(bp);
    float vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
    glm::vec3 cp = p - c;
    float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return glm::length(cp);
    float vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
    float va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
        return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
    float denom = 1.0f / (va + vb + vc);
    return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

// How far LOD 0's surface strays from a level: the largest distance from a LOD-0 vertex to the
// level's nearest triangle. meshoptimizer's error is the quadric distance of the kept vertices
// to the original planes, which stays near zero on curved surfaces whose removed vertices lie
// off the new, flatter triangles (a sphere's facets): the LOD would pop where it is chosen.
float surfaceDeviation(const std::vector<gpu::GpuVertex>& vertices,
                       const std::vector<uint32_t>& lod0, const std::vector<uint32_t>& level) {
    std::vector<uint8_t> used(vertices.size(), 0);
    for (uint32_t i : lod0) used[i] = 1;
    std::vector<uint32_t> points;
    for (uint32_t v = 0; v < vertices.size(); ++v)
        if (used[v]) points.push_back(v);
    size_t triangles = level.size() / 3;
    size_t stride = std::max<size_t>(
        1, size_t(double(points.size()) * double(triangles) / kMaxDeviationPairs) + 1);
    float worst = 0.0f;
    for (size_t k = 0; k < points.size(); k += stride) {
        glm::vec3 p = vertices[points[k]].position;
        float nearest = 1e30f;
        for (size_t t = 0; t < triangles && nearest > worst; ++t)
            nearest = std::min(nearest, pointTriangleDistance(p, vertices[level[3 * t]].position,
                                                              vertices[level[3 * t + 1]].position,
                                                              vertices[level[3 * t + 2]].position));
        worst = std::max(worst, nearest);
    }
    return worst;
}
} // namespace

gpu::GpuMeshLods appendMeshWithLods(MeshGeometry mesh, std::vector<gpu::GpuVertex>& vertices,
                                    std::vector<glm::vec2>* shadelUvs,
                                    std::vector<uint32_t>& indices,
                                    std::vector<uint32_t>* vertexSources) {
    size_t vertexCount = mesh.vertices.size();
    const float* positions = vertexCount ? &mesh.vertices[0].position.x : nullptr;
    constexpr size_t stride = sizeof(gpu::GpuVertex);
    std::vector<std::vector<uint32_t>> levels;
    std::vector<float> errors;
    const bool optimizable = maxValence(mesh.indices, vertexCount) <= kMaxOptimizedValence;
    if (!mesh.keepTriangleOrder && !mesh.indices.empty() && optimizable)
        meshopt_optimizeVertexCache(mesh.indices.data(), mesh.indices.data(), mesh.indices.size(),
                                    vertexCount);
    levels.push_back(mesh.indices);
    errors.push_back(0.0f);
    if (vertexCount > 0 && mesh.indices.size() >= 6 && optimizable) {
        float scale = meshopt_simplifyScale(positions, vertexCount, stride);
        float bound = kFirstLevelError;
        for (uint32_t k = 1; k < CULL_MAX_LODS && bound <= kMaxRelativeError; ++k, bound *= 4.0f) {
            size_t target = (mesh.indices.size() >> k) / 3 * 3;
            if (target < 3) break;
            std::vector<uint32_t> lod(mesh.indices.size());
            float error = 0.0f;
            size_t count =
                meshopt_simplify(lod.data(), mesh.indices.data(), mesh.indices.size(), positions,
                                 vertexCount, stride, target, bound, 0, &error);
            if (count < 3 || float(count) > kMinReduction * float(levels.back().size())) continue;
            lod.resize(count);
            meshopt_optimizeVertexCache(lod.data(), lod.data(), count, vertexCount);
            errors.push_back(std::max({error * scale, errors.back(),
                                       surfaceDeviation(mesh.vertices, mesh.indices, lod)}));
            levels.push_back(std::move(lod));
        }
    }

    // One fetch order for every level (LOD 0 first), applied to every vertex stream.
    std::vector<uint32_t> all;
    for (const auto& l : levels) all.insert(all.end(), l.begin(), l.end());
    std::vector<uint32_t> remap(vertexCount);
    size_t kept =
        meshopt_optimizeVertexFetchRemap(remap.data(), all.data(), all.size(), vertexCount);
    uint32_t vertexOffset = uint32_t(vertices.size());
    vertices.resize(vertexOffset + kept);
    meshopt_remapVertexBuffer(vertices.data() + vertexOffset, mesh.vertices.data(), vertexCount,
                              sizeof(gpu::GpuVertex), remap.data());
    if (shadelUvs) {
        shadelUvs->resize(vertexOffset + kept, glm::vec2(0.0f));
        if (!mesh.shadelUvs.empty())
            meshopt_remapVertexBuffer(shadelUvs->data() + vertexOffset, mesh.shadelUvs.data(),
                                      vertexCount, sizeof(glm::vec2), remap.data());
    }
    if (vertexSources) {
        vertexSources->resize(vertexOffset + kept, 0u);
        for (size_t v = 0; v < vertexCount; ++v)
            if (remap[v] != ~0u)
                (*vertexSources)[vertexOffset + remap[v]] =
                    mesh.sources.empty() ? uint32_t(v) : mesh.sources[v];
    }

    gpu::GpuMeshLods out{};
    out.lodCount = uint32_t(levels.size());
    for (size_t k = 0; k < levels.size(); ++k) {
        out.lod[k].firstIndex = uint32_t(indices.size());
        out.lod[k].indexCount = uint32_t(levels[k].size());
        out.lod[k].error = errors[k];
        for (uint32_t i : levels[k]) indices.push_back(remap[i]);
    }
    // Proxy index sets: each level again over the first vertex of every distinct position.
    const gpu::GpuVertex* mine = vertices.data() + vertexOffset;
    auto distinct = [&](const uint32_t* first, size_t count) {
        std::vector<uint8_t> seen(kept, 0);
        uint32_t n = 0;
        for (size_t i = 0; i < count; ++i) n += seen[first[i]]++ == 0 ? 1u : 0u;
        return n;
    };
    for (size_t k = 0; k < levels.size(); ++k) {
        std::vector<uint32_t> proxy(out.lod[k].indexCount);
        if (!proxy.empty())
            meshopt_generateShadowIndexBuffer(proxy.data(), indices.data() + out.lod[k].firstIndex,
                                              proxy.size(), mine, kept, sizeof(glm::vec3),
                                              sizeof(gpu::GpuVertex));
        out.lod[k].uniqueVertices = distinct(indices.data() + out.lod[k].firstIndex, proxy.size());
        out.lod[k].proxyUniqueVertices = distinct(proxy.data(), proxy.size());
        out.lod[k].proxyFirstIndex = uint32_t(indices.size());
        indices.insert(indices.end(), proxy.begin(), proxy.end());
    }
    return out;
}

} // namespace shadel
