#pragma once
// Per-mesh LOD chains for the unified geometry buffers (LODs in one buffer, the least
// detailed always resident), made with meshoptimizer: each level simplified from LOD 0 under an
// error bound (meshopt_simplify only removes vertices, so every level indexes LOD 0's vertices
// and a baked mesh's shadel UVs: one chart atlas for all LODs, switching never reallocates),
// vertex-cache ordered, and the mesh's vertices ordered for fetch.
#include <vector>

#include "common/shared_types.h"

namespace shadel {

struct MeshGeometry {
    std::vector<gpu::GpuVertex> vertices;
    std::vector<glm::vec2> shadelUvs; // parallel to vertices, or empty
    // Parallel to vertices, or empty (= 0, 1, 2...): what each vertex came from, carried through
    // the fetch reordering into `vertexSources` (animated playback rewrites posed vertices).
    std::vector<uint32_t> sources;
    std::vector<uint32_t> indices; // LOD 0, mesh-local
    // LOD 0's triangle order is meaningful (triangle-ID maps index it): do not reorder it.
    bool keepTriangleOrder = false;
};

// Appends the mesh (vertices, shadel UVs when `shadelUvs` is given, every LOD's indices) to the
// unified arrays. The returned levels' firstIndex are absolute; all share the mesh's
// vertexOffset (the vertex count before the call). With `vertexSources`, each appended vertex's
// `sources` entry is appended in the same order.
gpu::GpuMeshLods appendMeshWithLods(MeshGeometry mesh, std::vector<gpu::GpuVertex>& vertices,
                                    std::vector<glm::vec2>* shadelUvs,
                                    std::vector<uint32_t>& indices,
                                    std::vector<uint32_t>* vertexSources = nullptr);

} // namespace shadel
