#pragma once
// Geometry helpers shared by the importers: attribute repair (normals, tangents), splitting of
// primitives too large for 16-bit triangle IDs, and the procedural meshes the built-in scenes
// are made of.
#include <cstdint>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace shadel {

// Triangle IDs are 16-bit downstream and 0xFFFF is reserved for "no triangle".
constexpr uint32_t kMaxTrianglesPerMesh = 65535;

// Area-weighted smooth normals over shared (indexed) vertices. Vertices without any
// non-degenerate triangle get +Y.
void computeSmoothNormals(Mesh& mesh);

// Per-triangle UV-gradient tangents accumulated per vertex, orthogonalised against the normal,
// handedness in w: bitangent = cross(normal, tangent.xyz) * w points along -v, toward the
// texture's top row, which is +Y of a glTF normal map ("+Y is up"; glTF's UV origin is the
// top-left corner), as the glTF Sample Viewer's derivative tangents have it. Where the UVs give
// no direction an arbitrary unit tangent perpendicular to the normal is used. `uvSet` is the set
// the normal map reads (0: Vertex::uv0, 1: uv1), which glTF's tangents follow.
void computeTangents(Mesh& mesh, int uvSet = 0);

// Makes every normal and tangent finite and unit length (tangent perpendicular to the normal,
// w = ±1). Returns how many vertices needed repair.
uint32_t sanitizeNormalsAndTangents(Mesh& mesh);

void computeBounds(Mesh& mesh);

// Removes triangles that repeat an earlier one (the same three vertices in the same cyclic order:
// the same face, drawn again). Keeps the first of each, in order. Returns how many were removed.
// A strip of a million copies of one triangle would otherwise cost a million full-screen draws.
size_t removeDuplicateTriangles(std::vector<uint32_t>& indices);

// Splits a mesh into parts of at most maxTriangles triangles each, keeping triangle order and
// compacting vertices per part. A mesh already small enough comes back as the only element.
std::vector<Mesh> splitMesh(Mesh mesh, uint32_t maxTriangles = kMaxTrianglesPerMesh);

// The invariants every imported or built-in scene satisfies (for tests and debug checks): all
// indices in range, every mesh ≤ kMaxTrianglesPerMesh triangles, finite positions/UVs, unit
// normals, unit tangents perpendicular to them with w = ±1, valid material/texture/mesh indices,
// finite transforms, unit camera and light directions. Returns "" or the first violation.
std::string sceneInvariantViolation(const Scene& scene);

// Procedural meshes: outward normals, CCW seen from outside, tangents set, bounds set.
// UVs are in metres (u, v along the surface) so Material::proceduralScale = cells per metre.
Mesh makeBox(const std::string& name, glm::vec3 size, uint32_t material); // centred at origin
// XZ plane at y = 0 facing +Y, centred at origin; uv = (x, -z).
Mesh makePlane(const std::string& name, float sizeX, float sizeZ, uint32_t material,
               uint32_t subdivisions = 1);
Mesh makeSphere(const std::string& name, float radius, uint32_t material, uint32_t segments = 32,
                uint32_t rings = 16);
// Y axis, from y = 0 to y = height, with caps.
Mesh makeCylinder(const std::string& name, float radius, float height, uint32_t material,
                  uint32_t segments = 24);

} // namespace shadel
