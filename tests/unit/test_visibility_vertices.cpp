// The visibility prepass's own index buffer (scene/visibility_vertices.h): every triangle starts
// at a visibility vertex no other triangle starts at, which names the triangle; its corners are
// the scene's, in the scene's order; the draws' firstIndex and vertexOffset still apply.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "scene/visibility_vertices.h"

using namespace shadel;

namespace {

// The invariants, for every triangle of every range.
void expectVisibilityGeometry(const std::vector<uint32_t>& indices,
                              const std::vector<MeshIndexRange>& meshes,
                              const VisibilityGeometry& g) {
    ASSERT_EQ(g.indices.size(), indices.size());
    std::vector<int> provokes(g.vertices.size(), 0);
    for (const MeshIndexRange& m : meshes)
        for (uint32_t t = m.firstIndex; t < m.firstIndex + m.indexCount; t += 3) {
            uint32_t vis[3], scene[3];
            for (int k = 0; k < 3; ++k) {
                // What a draw fetches: index + vertexOffset.
                vis[k] = g.indices[t + k] + uint32_t(m.vertexOffset);
                ASSERT_LT(vis[k], g.vertices.size()) << "triangle " << t / 3;
                ASSERT_GE(vis[k], uint32_t(m.vertexOffset)) << "triangle " << t / 3;
                scene[k] = g.vertices[vis[k]].x;
            }
            // The provoking (first) vertex names the triangle, numbered within its mesh.
            EXPECT_EQ(g.vertices[vis[0]].y, (t - m.firstIndex) / 3);
            ++provokes[vis[0]];
            // The same corners in the same order (depth interpolates exactly as the scene's).
            for (int k = 0; k < 3; ++k)
                EXPECT_EQ(scene[k], indices[t + k] + uint32_t(m.vertexOffset))
                    << "triangle " << t / 3 << " corner " << k;
        }
    for (size_t v = 0; v < provokes.size(); ++v) EXPECT_LE(provokes[v], 1) << "vertex " << v;
}

} // namespace

TEST(VisibilityVertices, EveryTriangleStartsAtAVertexNamingIt) {
    // A quad (two triangles over four vertices) and a tetrahedron (four over four), the second
    // mesh at vertexOffset 4 after a LOD-like second range of the quad.
    std::vector<uint32_t> indices = {0, 1, 2, 2, 1, 3, /* quad LOD 1: */ 0, 1, 3, 0, 1, 2, 0, 3, 1,
                                     1, 3, 2, 2, 3, 0};
    std::vector<MeshIndexRange> meshes = {{0, 9, 0}, {9, 12, 4}};
    VisibilityGeometry g = buildVisibilityGeometry(indices, meshes);
    expectVisibilityGeometry(indices, meshes, g);
    // The quad's second triangle starts at vertex 2, which no triangle started at: shared with
    // the first triangle's third corner. The LOD's triangle starts at vertex 0 again: a duplicate.
    EXPECT_EQ(g.indices[3], g.indices[2]);
    EXPECT_NE(g.indices[6], g.indices[0]);
}

TEST(VisibilityVertices, TrianglesBeyondTheVertexCountDuplicateACorner) {
    // Six triangles over three vertices, each vertex first in two of them: the second triangle
    // starting at a vertex gets a duplicate.
    std::vector<uint32_t> indices = {0, 1, 2, 1, 2, 0, 2, 0, 1, 0, 2, 1, 0, 1, 2, 2, 1, 0};
    std::vector<MeshIndexRange> meshes = {{0, uint32_t(indices.size()), 7}};
    VisibilityGeometry g = buildVisibilityGeometry(indices, meshes);
    expectVisibilityGeometry(indices, meshes, g);
    // 7 unused slots before the mesh's offset, three shared vertices, three duplicates.
    EXPECT_EQ(g.vertices.size(), 7u + 3u + 3u);
    for (uint32_t v = 0; v < 7; ++v) EXPECT_EQ(g.vertices[v].y, kVisibilityNoTriangle);
}

TEST(VisibilityVertices, RandomMeshesKeepEveryInvariant) {
    std::mt19937 rng(12345);
    std::vector<uint32_t> indices;
    std::vector<MeshIndexRange> meshes;
    int32_t vertexOffset = 0;
    for (int mesh = 0; mesh < 20; ++mesh) {
        uint32_t vertices = 3 + rng() % 200;
        uint32_t triangles = rng() % 500;
        MeshIndexRange m{uint32_t(indices.size()), triangles * 3, vertexOffset};
        for (uint32_t i = 0; i < triangles * 3; ++i) indices.push_back(rng() % vertices);
        meshes.push_back(m);
        vertexOffset += int32_t(vertices);
    }
    VisibilityGeometry g = buildVisibilityGeometry(indices, meshes);
    expectVisibilityGeometry(indices, meshes, g);
    // Every triangle needs one vertex of its own; the others are shared, made once per vertex.
    EXPECT_LE(g.vertices.size(), indices.size() / 3 + size_t(vertexOffset));
}

TEST(VisibilityVertices, BadRangesAreRefused) {
    std::vector<uint32_t> indices = {0, 1, 2, 2, 1, 3};
    auto build = [&](MeshIndexRange m) {
        std::vector<MeshIndexRange> meshes = {m};
        return buildVisibilityGeometry(indices, meshes);
    };
    EXPECT_THROW(build({0, 9, 0}), std::logic_error);  // past the end
    EXPECT_THROW(build({0, 4, 0}), std::logic_error);  // not whole triangles
    EXPECT_THROW(build({1, 3, 0}), std::logic_error);  // not at a triangle
    EXPECT_THROW(build({0, 6, -1}), std::logic_error); // negative offset
    EXPECT_NO_THROW(build({0, 6, 0}));
}
