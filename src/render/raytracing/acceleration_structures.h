#pragma once
// Acceleration structures (seed 003): one BLAS per mesh LOD, built at load from the unified
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
