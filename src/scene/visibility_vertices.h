#pragma once
// Visibility IDs without gl_PrimitiveID (for render/shadel/visibility.h; here, beside the other
// geometry processing, so the CPU unit tests cover it). The visibility prepass must write, per
// pixel, which triangle won the depth test. Reading gl_PrimitiveID in the fragment shader is the
// plain way, but on lavapipe it costs the prepass dearly: builtin:many 1280x720, visibilityPrepass
// 107 ms with it against 80 without (the depth prepass: 63), builtin:default 15.6-18.7
// against 12.4-12.9. Instead each triangle gets a provoking vertex of its own that carries the
// triangle's number as a flat attribute: the visibility prepass draws a second index buffer, the
// scene's with every triangle's first corner a "visibility vertex" no other triangle starts at; a
// visibility vertex names the scene vertex it stands for (positions and everything else are pulled
// from there, exactly as the other passes pull them) and the triangle it is provoking for. Where
// the first corner's vertex already starts another triangle, it is duplicated; meshes have about
// two triangles per vertex, so there are about as many visibility vertices as triangles plus half
// the vertices. The corners keep their order, so the prepass writes the depth the scene's
// indices give (the forward passes after it test EQUAL).
//
// The indices keep the scene's layout (every LOD and proxy range where the scene has it), so the
// culled draw commands (firstIndex, vertexOffset) draw them unchanged: a visibility vertex of a
// mesh lies at or after the mesh's vertexOffset, and its index is stored relative to it.
// Triangles are numbered within their mesh's range, from its first index: LOD 0's numbering (what
// gl_PrimitiveID gives LOD 0 draws), which the mesh's other LODs and proxies continue, so the
// visibility buffer's triangle finds its vertices whatever LOD was drawn.
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace shadel {

// A mesh's part of the scene's index buffer: its triangles (every LOD and proxy) and the
// vertexOffset its draws add.
struct MeshIndexRange {
    uint32_t firstIndex = 0;
    uint32_t indexCount = 0; // a multiple of 3
    int32_t vertexOffset = 0;
};

inline constexpr uint32_t kVisibilityNoTriangle = 0xFFFFFFFFu; // a vertex that starts none

struct VisibilityGeometry {
    std::vector<uint32_t> indices;    // as the scene's, each triangle first at its own vertex
    std::vector<glm::uvec2> vertices; // (scene vertex, triangle of the mesh it starts)
};

// Linear in the indices. The ranges come from the scene upload, so a range that leaves the index
// buffer, is not whole triangles or overlaps the one before throws std::logic_error.
VisibilityGeometry buildVisibilityGeometry(std::span<const uint32_t> indices,
                                           std::span<const MeshIndexRange> meshes);

} // namespace shadel
