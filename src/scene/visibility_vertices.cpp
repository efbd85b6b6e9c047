#include "scene/visibility_vertices.h"

#include <algorithm>
#include <stdexcept>

namespace shadel {

VisibilityGeometry buildVisibilityGeometry(std::span<const uint32_t> indices,
                                           std::span<const MeshIndexRange> meshes) {
    VisibilityGeometry out;
    out.indices.assign(indices.begin(), indices.end());
    out.vertices.reserve(indices.size() / 3 + indices.size() / 6);
    uint64_t end = 0;             // of the range before
    std::vector<uint32_t> shared; // per mesh vertex: its first visibility vertex, or none
    for (const MeshIndexRange& m : meshes) {
        uint64_t last = uint64_t(m.firstIndex) + m.indexCount;
        if (m.indexCount % 3 != 0 || last > indices.size() || m.firstIndex < end ||
            m.firstIndex % 3 != 0 || m.vertexOffset < 0)
            throw std::logic_error("buildVisibilityGeometry: bad mesh index range");
        end = last;
        if (m.indexCount == 0) continue;
        // A mesh's visibility vertices lie at or after its vertexOffset, so the indices relative
        // to it (what its draws add the offset to) are never negative.
        uint32_t base = uint32_t(std::max<size_t>(out.vertices.size(), size_t(m.vertexOffset)));
        out.vertices.resize(base, glm::uvec2(0u, kVisibilityNoTriangle)); // never drawn
        uint32_t meshVertices = 0;
        for (uint64_t i = m.firstIndex; i < last; ++i)
            meshVertices = std::max(meshVertices, indices[i] + 1u);
        shared.assign(meshVertices, kVisibilityNoTriangle);
        // Where vertex v is drawn from: its shared visibility vertex (made on first use).
        auto sharedOf = [&](uint32_t v) {
            if (shared[v] == kVisibilityNoTriangle) {
                shared[v] = uint32_t(out.vertices.size());
                out.vertices.push_back({uint32_t(m.vertexOffset) + v, kVisibilityNoTriangle});
            }
            return shared[v];
        };
        auto startsNothing = [&](uint32_t v) {
            return shared[v] == kVisibilityNoTriangle ||
                   out.vertices[shared[v]].y == kVisibilityNoTriangle;
        };
        for (uint64_t t = m.firstIndex; t < last; t += 3) {
            uint32_t corner[3] = {indices[t], indices[t + 1], indices[t + 2]};
            uint32_t triangle = uint32_t((t - m.firstIndex) / 3); // within the mesh
            // The first corner provokes: its shared visibility vertex when that starts no other
            // triangle yet, else a duplicate. The corners stay in order (no turning to a free
            // corner, which would need fewer duplicates): a rasterizer interpolates depth from
            // the corners in order, and the forward passes after the prepass test EQUAL against
            // its depth with the scene's own indices.
            uint32_t provoking;
            if (startsNothing(corner[0])) {
                provoking = sharedOf(corner[0]);
                out.vertices[provoking].y = triangle;
            } else {
                provoking = uint32_t(out.vertices.size());
                out.vertices.push_back({uint32_t(m.vertexOffset) + corner[0], triangle});
            }
            out.indices[t] = provoking - uint32_t(m.vertexOffset);
            out.indices[t + 1] = sharedOf(corner[1]) - uint32_t(m.vertexOffset);
            out.indices[t + 2] = sharedOf(corner[2]) - uint32_t(m.vertexOffset);
        }
    }
    return out;
}

} // namespace shadel
