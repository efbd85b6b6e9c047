#pragma once
// Mesh distance fields: a signed distance field per mesh on a regular voxel grid in
// object space, built on the CPU at bake time and cached on disk next to the bakes. The GPU
// keeps them in one 3-D atlas (render/distance_fields) and sphere-traces far soft shadows and
// ambient occlusion through them.
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace shadel {

struct MeshDistanceField {
    glm::uvec3 resolution{0}; // voxels per axis
    glm::vec3 origin{0.0f};   // object-space centre of voxel (0, 0, 0)
    float voxelSize = 0.0f;   // metres (object space)
    // Signed distance at each voxel centre (x fastest, then y, then z), negative inside, in
    // object-space metres. Meshes that are not closed (a ground plane) count as solid below
    // their surface along the voxel's test rays, which is what shadow rays want.
    std::vector<float> distances;
    float at(uint32_t x, uint32_t y, uint32_t z) const {
        return distances[(size_t(z) * resolution.y + y) * resolution.x + x];
    }
};

// Voxels along the mesh's longest side (plus a border of two voxels on every side).
constexpr uint32_t kDistanceFieldResolution = 24;

// Exact distance to the nearest triangle (brute force: meshes here have a few thousand
// triangles); the sign from three rays' crossing parities (majority).
MeshDistanceField buildMeshDistanceField(const Mesh& mesh,
                                         uint32_t resolution = kDistanceFieldResolution);

// The cached field of `mesh` (cacheDir as the bake cache's; "" = no cache): read when a file
// with the mesh's key checks out, else built and written atomically. `*fromCache` says which.
MeshDistanceField loadOrBuildMeshDistanceField(const Mesh& mesh, const std::string& cacheDir,
                                               bool* fromCache = nullptr,
                                               uint32_t resolution = kDistanceFieldResolution);

} // namespace shadel
