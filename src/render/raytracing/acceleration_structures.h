#pragma once
// Acceleration structures: one BLAS per mesh LOD, built at load from the unified
// geometry and compacted into TLSF pools (blas_pools.h), least-detailed LODs first so that a
// failed allocation can always fall back to the mesh's least-detailed BLAS; and the TLAS,
// rebuilt every frame from the instances the CPU keeps (ray-tracing distance, not the frustum).
#include <memory>
#include <vector>

#include "render/gpu_scene.h"
#include "render/raytracing/blas_pools.h"

namespace shadel {

// VK_KHR_acceleration_structure entry points (not exported by the loader).
struct RtFunctions {
    PFN_vkCreateAccelerationStructureKHR create = nullptr;
    PFN_vkDestroyAccelerationStructureKHR destroy = nullptr;
    PFN_vkGetAccelerationStructureBuildSizesKHR buildSizes = nullptr;
    PFN_vkCmdBuildAccelerationStructuresKHR cmdBuild = nullptr;
    PFN_vkCmdCopyAccelerationStructureKHR cmdCopy = nullptr;
    PFN_vkCmdWriteAccelerationStructuresPropertiesKHR cmdWriteProperties = nullptr;
    PFN_vkGetAccelerationStructureDeviceAddressKHR address = nullptr;
};
RtFunctions loadRtFunctions(const Device& device);

struct Blas {
    VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
    VkDeviceAddress address = 0;
    BlasRange memory;
    uint32_t firstIndex = 0; // the LOD's range in the unified index buffer (hit shading)
    uint32_t mesh = 0, lod = 0;
};

struct BlasSetStats {
    uint32_t built = 0;
    uint64_t bytes = 0;            // compacted, in the pools
    uint64_t uncompactedBytes = 0; // what the builds needed before compaction
    uint32_t fallbacks = 0;        // LODs whose allocation failed: they use the least-detailed BLAS
    uint32_t meshesWithoutBlas = 0; // even the least-detailed BLAS failed: not ray traced
};

struct BlasSet {
    std::vector<Blas> blases;
    // Per mesh, per LOD: index into blases (the least-detailed one's after a failed allocation),
    // or -1 (no BLAS: the mesh is left out of the TLAS).
    std::vector<std::vector<int32_t>> meshLods;
    BlasSetStats stats;
};

void buildBlases(Gpu& gpu, const RtFunctions& fn, BlasPools& pools, const GpuScene& scene,
                 BlasSet& out);
void destroyBlases(Gpu& gpu, const RtFunctions& fn, BlasPools& pools, BlasSet& set);

// Animated (GPU-skinned) meshes: one BLAS per mesh over its LOD 0, read from the deformed vertex
// buffer (render/skinning), built with ALLOW_UPDATE so a changed pose is a refit
// (VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE) instead of a build; a refit keeps the first
// build's tree, whose boxes loosen as the pose departs from it, so every kRefitsPerRebuild refits
// it is built again. Storage in the BLAS pools (not compacted: an updatable BLAS is refit in
// place); without room the mesh keeps its static (bind-pose) BLAS.
struct AnimatedBlas {
    uint32_t mesh = 0;
    VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
    VkDeviceAddress address = 0;
    BlasRange memory;
    BufferHandle scratch; // max(build, update) scratch, this BLAS's own
    VkDeviceAddress scratchAddress = 0;
    VkAccelerationStructureGeometryKHR geometry{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    uint32_t firstIndex = 0, triangles = 0;
    bool built = false;
    uint64_t builtPose = 0;       // skin pose version it was last built or refit for
    uint64_t lastUpdateFrame = 0; // frame of that build or refit
    uint32_t refitsSinceBuild = 0;
};
constexpr uint32_t kRefitsPerRebuild = 8;

struct AnimatedBlasSet {
    std::vector<AnimatedBlas> blases;
    std::vector<int32_t> byMesh; // index into blases, or -1
    uint32_t withoutRoom = 0;    // skinned meshes the pools had no room for (static BLAS kept)
    uint64_t refits = 0, rebuilds = 0; // over the run; rebuilds include each first build
};

// `deformedVertices`: the skinned vertex buffer's address (the unified layout).
void createAnimatedBlases(Gpu& gpu, const RtFunctions& fn, BlasPools& pools, const GpuScene& scene,
                          const std::vector<uint32_t>& meshes, VkDeviceAddress deformedVertices,
                          AnimatedBlasSet& out);
void destroyAnimatedBlases(Gpu& gpu, const RtFunctions& fn, BlasPools& pools, AnimatedBlasSet& set);
// One build or refit per listed BLAS (rebuild: MODE_BUILD, else MODE_UPDATE), after the skinning
// pass's writes, with the barriers that order them before the TLAS build and ray queries.
struct AnimatedBlasUpdate {
    uint32_t blas = 0;
    bool rebuild = false;
};
void recordAnimatedBlasUpdates(Gpu& gpu, const RtFunctions& fn, VkCommandBuffer cmd,
                               AnimatedBlasSet& set,
                               const std::vector<AnimatedBlasUpdate>& updates);

// The top level: storage and scratch sized for every instance of the scene, rebuilt each frame.
struct Tlas {
    VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
    VkDeviceAddress address = 0;
    BufferHandle storage, scratch;
    BufferHandle instances; // host-visible VkAccelerationStructureInstanceKHR[maxInstances]
    VkDeviceAddress scratchAddress = 0; // aligned
    uint32_t maxInstances = 0;
    uint32_t instanceCount = 0; // this frame's
};

void createTlas(Gpu& gpu, const RtFunctions& fn, uint32_t maxInstances, Tlas& out);
void destroyTlas(Gpu& gpu, const RtFunctions& fn, Tlas& tlas);
// Records the build of `tlas.instanceCount` instances already written to `tlas.instances`, and
// the barrier that makes it visible to ray queries in fragment and compute shaders.
void recordTlasBuild(Gpu& gpu, const RtFunctions& fn, VkCommandBuffer cmd, const Tlas& tlas);

} // namespace shadel
