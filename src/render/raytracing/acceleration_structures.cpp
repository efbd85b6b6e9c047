#include "render/raytracing/acceleration_structures.h"

#include <algorithm>
#include <cstring>

#include "core/log.h"

namespace shadel {

RtFunctions loadRtFunctions(const Device& device) {
    RtFunctions fn;
    auto get = [&](const char* name) { return vkGetDeviceProcAddr(device.device, name); };
    fn.create = (PFN_vkCreateAccelerationStructureKHR)get("vkCreateAccelerationStructureKHR");
    fn.destroy = (PFN_vkDestroyAccelerationStructureKHR)get("vkDestroyAccelerationStructureKHR");
    fn.buildSizes =
        (PFN_vkGetAccelerationStructureBuildSizesKHR)get("vkGetAccelerationStructureBuildSizesKHR");
    fn.cmdBuild =
        (PFN_vkCmdBuildAccelerationStructuresKHR)get("vkCmdBuildAccelerationStructuresKHR");
    fn.cmdCopy = (PFN_vkCmdCopyAccelerationStructureKHR)get("vkCmdCopyAccelerationStructureKHR");
    fn.cmdWriteProperties = (PFN_vkCmdWriteAccelerationStructuresPropertiesKHR)get(
        "vkCmdWriteAccelerationStructuresPropertiesKHR");
    fn.address = (PFN_vkGetAccelerationStructureDeviceAddressKHR)get(
        "vkGetAccelerationStructureDeviceAddressKHR");
    if (!fn.create || !fn.destroy || !fn.buildSizes || !fn.cmdBuild || !fn.cmdCopy ||
        !fn.cmdWriteProperties || !fn.address)
        throw DeviceError(format("%s: VK_KHR_acceleration_structure entry points are missing",
                                 device.name.c_str()));
    return fn;
}

static VkDeviceSize alignUp(VkDeviceSize v, VkDeviceSize a) {
    return (v + a - 1) / a * a;
}

static VkDeviceSize scratchAlignment(const Device& device) {
    VkPhysicalDeviceAccelerationStructurePropertiesKHR as{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR};
    VkPhysicalDeviceProperties2 p{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    p.pNext = &as;
    vkGetPhysicalDeviceProperties2(device.physical, &p);
    return std::max<VkDeviceSize>(as.minAccelerationStructureScratchOffsetAlignment, 256);
}

static VkAccelerationStructureKHR createAs(Gpu& gpu, const RtFunctions& fn, VkBuffer buffer,
                                           VkDeviceSize offset, VkDeviceSize size,
                                           VkAccelerationStructureTypeKHR type,
                                           const std::string& name) {
    VkAccelerationStructureCreateInfoKHR ci{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    ci.buffer = buffer;
    ci.offset = offset;
    ci.size = size;
    ci.type = type;
    VkAccelerationStructureKHR as = VK_NULL_HANDLE;
    VK_CHECK(fn.create(gpu.device.device, &ci, nullptr, &as));
    setName(gpu.device, as, VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, name);
    return as;
}

static VkDeviceAddress asAddress(Gpu& gpu, const RtFunctions& fn, VkAccelerationStructureKHR as) {
    VkAccelerationStructureDeviceAddressInfoKHR info{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
    info.accelerationStructure = as;
    return fn.address(gpu.device.device, &info);
}

namespace {

struct BlasJob {
    uint32_t mesh = 0, lod = 0;
    uint32_t firstIndex = 0, triangles = 0;
    VkAccelerationStructureGeometryKHR geometry{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    VkAccelerationStructureBuildSizesInfoKHR sizes{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    VkDeviceSize asOffset = 0, scratchOffset = 0; // in the batch's temporary buffers
    VkAccelerationStructureKHR temporary = VK_NULL_HANDLE;
};

// Vertices per mesh: meshes lie one after another in the unified vertex buffer.
std::vector<uint32_t> meshVertexCounts(const Gpu& gpu, const GpuScene& scene) {
    uint32_t total = uint32_t(size(gpu, scene.vertices) / sizeof(gpu::GpuVertex));
    std::vector<uint32_t> order(scene.meshInfo.size());
    for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        return scene.meshInfo[a].vertexOffset < scene.meshInfo[b].vertexOffset;
    });
    std::vector<uint32_t> counts(order.size(), 0);
    for (size_t k = 0; k < order.size(); ++k) {
        uint32_t begin = uint32_t(scene.meshInfo[order[k]].vertexOffset);
        uint32_t end =
            k + 1 < order.size() ? uint32_t(scene.meshInfo[order[k + 1]].vertexOffset) : total;
        counts[order[k]] = end > begin ? end - begin : 0;
    }
    return counts;
}

BufferHandle temporaryBuffer(Gpu& gpu, const char* name, VkDeviceSize size,
                             VkBufferUsageFlags usage) {
    BufferHandle b = createBuffer(gpu, {name, std::max<VkDeviceSize>(size, 256), usage});
    if (!b)
        throw DeviceError(
            format("out of GPU memory for %s (%llu bytes)", name, (unsigned long long)size));
    return b;
}

} // namespace

// Builds one batch: every job into a temporary (uncompacted) BLAS, reads the compacted sizes,
// then allocates each from the pools in job order and copies it there compacted. A failed
// allocation maps the LOD to the mesh's least-detailed BLAS (built in an earlier position of
// the order: least-detailed LODs of every mesh come first).
// One triangle geometry's BLAS build info: static BLASes are compacted and fast to trace,
// animated ones (refit every pose) fast to build and updatable.
constexpr VkBuildAccelerationStructureFlagsKHR kStaticBlasFlags =
    VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR |
    VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR;
constexpr VkBuildAccelerationStructureFlagsKHR kAnimatedBlasFlags =
    VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR |
    VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;

static VkAccelerationStructureBuildGeometryInfoKHR
blasBuildInfo(const VkAccelerationStructureGeometryKHR& geometry,
              VkBuildAccelerationStructureFlagsKHR flags) {
    VkAccelerationStructureBuildGeometryInfoKHR b{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    b.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    b.flags = flags;
    b.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    b.geometryCount = 1;
    b.pGeometries = &geometry;
    return b;
}

static void buildBatch(Gpu& gpu, const RtFunctions& fn, BlasPools& pools,
                       std::vector<BlasJob>& jobs, VkDeviceSize asBytes, VkDeviceSize scratchBytes,
                       VkDeviceSize scratchAlign, BlasSet& out) {
    if (jobs.empty()) return;
    BufferHandle asBuffer = temporaryBuffer(gpu, "rt.blasBuild", asBytes,
                                            VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
    BufferHandle scratch = temporaryBuffer(gpu, "rt.blasScratch", scratchBytes + scratchAlign, 0);
    VkDeviceAddress scratchBase = alignUp(address(gpu, scratch), scratchAlign);
    for (BlasJob& j : jobs)
        j.temporary = createAs(gpu, fn, vkBuffer(gpu, asBuffer), j.asOffset,
                               j.sizes.accelerationStructureSize,
                               VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                               format("rt.blasBuild.mesh%u.lod%u", j.mesh, j.lod));
    VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qci.queryType = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR;
    qci.queryCount = uint32_t(jobs.size());
    VkQueryPool queries = VK_NULL_HANDLE;
    VK_CHECK(vkCreateQueryPool(gpu.device.device, &qci, nullptr, &queries));

    std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos(jobs.size());
    std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges(jobs.size());
    std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> rangePtrs(jobs.size());
    std::vector<VkAccelerationStructureKHR> handles(jobs.size());
    for (size_t i = 0; i < jobs.size(); ++i) {
        VkAccelerationStructureBuildGeometryInfoKHR& b = infos[i];
        b = blasBuildInfo(jobs[i].geometry, kStaticBlasFlags);
        b.dstAccelerationStructure = jobs[i].temporary;
        b.scratchData.deviceAddress = scratchBase + jobs[i].scratchOffset;
        ranges[i] = {jobs[i].triangles, 0, 0, 0};
        rangePtrs[i] = &ranges[i];
        handles[i] = jobs[i].temporary;
    }
    immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
        beginLabel(gpu, cmd, "rtBuildBlases");
        vkCmdResetQueryPool(cmd, queries, 0, uint32_t(jobs.size()));
        fn.cmdBuild(cmd, uint32_t(infos.size()), infos.data(), rangePtrs.data());
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                      VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
                      VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                      VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
        fn.cmdWriteProperties(cmd, uint32_t(handles.size()), handles.data(),
                              VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, queries, 0);
        endLabel(gpu, cmd);
    });
    std::vector<uint64_t> compacted(jobs.size(), 0);
    VK_CHECK(vkGetQueryPoolResults(
        gpu.device.device, queries, 0, uint32_t(jobs.size()), compacted.size() * sizeof(uint64_t),
        compacted.data(), sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    vkDestroyQueryPool(gpu.device.device, queries, nullptr);

    std::vector<std::pair<VkAccelerationStructureKHR, VkAccelerationStructureKHR>> copies;
    for (size_t i = 0; i < jobs.size(); ++i) {
        const BlasJob& j = jobs[i];
        out.stats.uncompactedBytes += j.sizes.accelerationStructureSize;
        std::vector<int32_t>& lods = out.meshLods[j.mesh];
        std::optional<BlasRange> range = pools.allocate(compacted[i]);
        if (!range) {
            // A BLAS allocation may fail (the pools are bounded): the mesh's least-detailed
            // BLAS stands in for the missing LOD, so the mesh still casts rays.
            int32_t fallback = lods.back();
            bool isLeastDetailed = j.lod + 1 == lods.size();
            if (isLeastDetailed || fallback < 0) {
                out.stats.meshesWithoutBlas += isLeastDetailed ? 1 : 0;
                lods[j.lod] = -1;
            } else {
                lods[j.lod] = fallback;
                out.stats.fallbacks++;
            }
            continue;
        }
        Blas blas;
        blas.memory = *range;
        blas.handle = createAs(gpu, fn, range->buffer, range->offset, compacted[i],
                               VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                               format("rt.blas.mesh%u.lod%u", j.mesh, j.lod));
        blas.address = asAddress(gpu, fn, blas.handle);
        blas.firstIndex = j.firstIndex;
        blas.mesh = j.mesh;
        blas.lod = j.lod;
        lods[j.lod] = int32_t(out.blases.size());
        out.blases.push_back(blas);
        out.stats.built++;
        out.stats.bytes += compacted[i];
        copies.push_back({j.temporary, blas.handle});
    }
    if (!copies.empty())
        immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
            beginLabel(gpu, cmd, "rtCompactBlases");
            for (auto& [src, dst] : copies) {
                VkCopyAccelerationStructureInfoKHR c{
                    VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
                c.src = src;
                c.dst = dst;
                c.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR;
                fn.cmdCopy(cmd, &c);
            }
            endLabel(gpu, cmd);
        });
    for (BlasJob& j : jobs) fn.destroy(gpu.device.device, j.temporary, nullptr);
    destroy(gpu, asBuffer);
    destroy(gpu, scratch);
    jobs.clear();
}

// One opaque triangle geometry: mesh m's vertices in the unified layout at `vertices` (the
// scene's, or GPU-skinned ones laid out alike), its indices from `firstIndex`.
static VkAccelerationStructureGeometryKHR
meshTriangles(const GpuScene& scene, uint32_t m, VkDeviceAddress vertices, uint32_t vertexCount,
              VkDeviceAddress indices, uint32_t firstIndex) {
    VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    g.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    VkAccelerationStructureGeometryTrianglesDataKHR& t = g.geometry.triangles;
    t = {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR};
    t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    t.vertexData.deviceAddress =
        vertices + VkDeviceSize(scene.meshInfo[m].vertexOffset) * sizeof(gpu::GpuVertex);
    t.vertexStride = sizeof(gpu::GpuVertex);
    t.maxVertex = vertexCount - 1;
    t.indexType = VK_INDEX_TYPE_UINT32;
    t.indexData.deviceAddress = indices + VkDeviceSize(firstIndex) * 4;
    return g;
}

void buildBlases(Gpu& gpu, const RtFunctions& fn, BlasPools& pools, const GpuScene& scene,
                 BlasSet& out) {
    out = {};
    std::vector<uint32_t> vertexCounts = meshVertexCounts(gpu, scene);
    VkDeviceAddress vertices = address(gpu, scene.vertices);
    VkDeviceAddress indices = address(gpu, scene.indices);
    VkDeviceSize scratchAlign = scratchAlignment(gpu.device);
    uint32_t maxLods = 0;
    out.meshLods.resize(scene.meshInfo.size());
    for (size_t m = 0; m < scene.meshInfo.size(); ++m) {
        out.meshLods[m].assign(scene.lodInfo[m].lodCount, -1);
        maxLods = std::max(maxLods, scene.lodInfo[m].lodCount);
    }
    // Least-detailed LODs of every mesh first, then finer ones: under a pool limit it is the
    // finest (largest) BLASes that fail, and their fallback always exists.
    constexpr VkDeviceSize kBatchBytes = 64ull << 20;
    std::vector<BlasJob> batch;
    VkDeviceSize asBytes = 0, scratchBytes = 0;
    for (uint32_t step = 0; step < maxLods; ++step) {
        for (uint32_t m = 0; m < scene.meshInfo.size(); ++m) {
            const gpu::GpuMeshLods& chain = scene.lodInfo[m];
            if (step >= chain.lodCount || vertexCounts[m] == 0) continue;
            BlasJob j;
            j.mesh = m;
            j.lod = chain.lodCount - 1 - step;
            j.firstIndex = chain.lod[j.lod].firstIndex;
            j.triangles = chain.lod[j.lod].indexCount / 3;
            if (j.triangles == 0) continue;
            j.geometry = meshTriangles(scene, m, vertices, vertexCounts[m], indices, j.firstIndex);
            VkAccelerationStructureBuildGeometryInfoKHR b =
                blasBuildInfo(j.geometry, kStaticBlasFlags);
            fn.buildSizes(gpu.device.device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &b,
                          &j.triangles, &j.sizes);
            if (!batch.empty() && asBytes + j.sizes.accelerationStructureSize > kBatchBytes) {
                buildBatch(gpu, fn, pools, batch, asBytes, scratchBytes, scratchAlign, out);
                asBytes = scratchBytes = 0;
            }
            j.asOffset = asBytes;
            j.scratchOffset = scratchBytes;
            asBytes = alignUp(asBytes + j.sizes.accelerationStructureSize, 256);
            scratchBytes = alignUp(scratchBytes + j.sizes.buildScratchSize, scratchAlign);
            batch.push_back(j);
        }
    }
    buildBatch(gpu, fn, pools, batch, asBytes, scratchBytes, scratchAlign, out);
    SHADEL_DEBUG("rt: %u BLASes (%.1f MiB compacted from %.1f MiB), %u fallbacks, %u meshes "
                 "without one",
                 out.stats.built, double(out.stats.bytes) / (1 << 20),
                 double(out.stats.uncompactedBytes) / (1 << 20), out.stats.fallbacks,
                 out.stats.meshesWithoutBlas);
}

void destroyBlases(Gpu& gpu, const RtFunctions& fn, BlasPools& pools, BlasSet& set) {
    for (Blas& b : set.blases) {
        fn.destroy(gpu.device.device, b.handle, nullptr);
        pools.free(b.memory);
    }
    set = {};
}

static VkAccelerationStructureBuildGeometryInfoKHR animatedBuildInfo(const AnimatedBlas& a) {
    return blasBuildInfo(a.geometry, kAnimatedBlasFlags);
}

void createAnimatedBlases(Gpu& gpu, const RtFunctions& fn, BlasPools& pools, const GpuScene& scene,
                          const std::vector<uint32_t>& meshes, VkDeviceAddress deformedVertices,
                          AnimatedBlasSet& out) {
    out = {};
    out.byMesh.assign(scene.meshInfo.size(), -1);
    std::vector<uint32_t> vertexCounts = meshVertexCounts(gpu, scene);
    VkDeviceAddress indices = address(gpu, scene.indices);
    VkDeviceSize scratchAlign = scratchAlignment(gpu.device);
    for (uint32_t m : meshes) {
        if (m >= scene.meshInfo.size() || vertexCounts[m] == 0 || scene.lodInfo[m].lodCount == 0)
            continue;
        AnimatedBlas a;
        a.mesh = m;
        a.firstIndex = scene.lodInfo[m].lod[0].firstIndex;
        a.triangles = scene.lodInfo[m].lod[0].indexCount / 3;
        if (a.triangles == 0) continue;
        a.geometry =
            meshTriangles(scene, m, deformedVertices, vertexCounts[m], indices, a.firstIndex);
        VkAccelerationStructureBuildGeometryInfoKHR b = animatedBuildInfo(a);
        VkAccelerationStructureBuildSizesInfoKHR sizes{
            VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
        fn.buildSizes(gpu.device.device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &b,
                      &a.triangles, &sizes);
        std::optional<BlasRange> range = pools.allocate(sizes.accelerationStructureSize);
        if (!range) {
            out.withoutRoom++;
            continue;
        }
        a.memory = *range;
        a.handle = createAs(gpu, fn, range->buffer, range->offset, sizes.accelerationStructureSize,
                            VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                            format("rt.blas.animated.mesh%u", m));
        a.address = asAddress(gpu, fn, a.handle);
        VkDeviceSize scratch = std::max(sizes.buildScratchSize, sizes.updateScratchSize);
        a.scratch = temporaryBuffer(gpu, "rt.blasAnimatedScratch", scratch + scratchAlign, 0);
        a.scratchAddress = alignUp(address(gpu, a.scratch), scratchAlign);
        out.byMesh[m] = int32_t(out.blases.size());
        out.blases.push_back(a);
    }
}

void destroyAnimatedBlases(Gpu& gpu, const RtFunctions& fn, BlasPools& pools,
                           AnimatedBlasSet& set) {
    for (AnimatedBlas& a : set.blases) {
        fn.destroy(gpu.device.device, a.handle, nullptr);
        pools.free(a.memory);
        destroy(gpu, a.scratch);
    }
    set = {};
}

void recordAnimatedBlasUpdates(Gpu& gpu, const RtFunctions& fn, VkCommandBuffer cmd,
                               AnimatedBlasSet& set,
                               const std::vector<AnimatedBlasUpdate>& updates) {
    if (updates.empty()) return;
    // The skinning pass wrote the vertices these read; last frame's ray queries (and TLAS
    // build) read the BLASes they overwrite.
    memoryBarrier(cmd,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
                      VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                  VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |
                      VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR,
                  VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                  VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR |
                      VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR);
    std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
    std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges(updates.size());
    std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> rangePtrs;
    for (size_t i = 0; i < updates.size(); ++i) {
        AnimatedBlas& a = set.blases[updates[i].blas];
        bool rebuild = updates[i].rebuild;
        VkAccelerationStructureBuildGeometryInfoKHR b = animatedBuildInfo(a);
        b.mode = rebuild ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR
                         : VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
        b.srcAccelerationStructure = rebuild ? VK_NULL_HANDLE : a.handle; // refit in place
        b.dstAccelerationStructure = a.handle;
        b.scratchData.deviceAddress = a.scratchAddress;
        infos.push_back(b);
        ranges[i] = {a.triangles, 0, 0, 0};
        rangePtrs.push_back(&ranges[i]);
    }
    beginLabel(gpu, cmd, "rtUpdateAnimatedBlases");
    fn.cmdBuild(cmd, uint32_t(infos.size()), infos.data(), rangePtrs.data());
    endLabel(gpu, cmd);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                  VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
                  VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR |
                      VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
                      VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
}

void createTlas(Gpu& gpu, const RtFunctions& fn, uint32_t maxInstances, Tlas& out) {
    out.maxInstances = std::max(maxInstances, 1u);
    out.instances = createBuffer(
        gpu,
        {"rt.tlasInstances", out.maxInstances * sizeof(VkAccelerationStructureInstanceKHR),
         VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR, MemoryKind::Upload});
    if (!out.instances) throw DeviceError("out of GPU memory for the TLAS instances");
    VkAccelerationStructureGeometryKHR geometry{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    geometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    geometry.geometry.instances = {
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR};
    geometry.geometry.instances.data.deviceAddress = address(gpu, out.instances);
    VkAccelerationStructureBuildGeometryInfoKHR b{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    b.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
    b.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    b.geometryCount = 1;
    b.pGeometries = &geometry;
    VkAccelerationStructureBuildSizesInfoKHR sizes{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    fn.buildSizes(gpu.device.device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &b,
                  &out.maxInstances, &sizes);
    VkDeviceSize align = scratchAlignment(gpu.device);
    out.storage = createBuffer(gpu, {"rt.tlas", sizes.accelerationStructureSize,
                                     VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR});
    out.scratch = createBuffer(gpu, {"rt.tlasScratch", sizes.buildScratchSize + align, 0});
    if (!out.storage || !out.scratch) throw DeviceError("out of GPU memory for the TLAS");
    out.scratchAddress = alignUp(address(gpu, out.scratch), align);
    out.handle = createAs(gpu, fn, vkBuffer(gpu, out.storage), 0, sizes.accelerationStructureSize,
                          VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, "rt.tlas");
    out.address = asAddress(gpu, fn, out.handle);
}

void destroyTlas(Gpu& gpu, const RtFunctions& fn, Tlas& tlas) {
    if (tlas.handle) fn.destroy(gpu.device.device, tlas.handle, nullptr);
    for (BufferHandle b : {tlas.storage, tlas.scratch, tlas.instances})
        if (b) destroy(gpu, b);
    tlas = {};
}

void recordTlasBuild(Gpu& gpu, const RtFunctions& fn, VkCommandBuffer cmd, const Tlas& tlas) {
    VkAccelerationStructureGeometryKHR geometry{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    geometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    geometry.geometry.instances = {
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR};
    geometry.geometry.instances.data.deviceAddress = address(gpu, tlas.instances);
    VkAccelerationStructureBuildGeometryInfoKHR b{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    b.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
    b.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    b.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    b.dstAccelerationStructure = tlas.handle;
    b.geometryCount = 1;
    b.pGeometries = &geometry;
    b.scratchData.deviceAddress = tlas.scratchAddress;
    VkAccelerationStructureBuildRangeInfoKHR range{tlas.instanceCount, 0, 0, 0};
    const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
    // Last frame's ray queries read the TLAS this build overwrites.
    memoryBarrier(cmd,
                  VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR,
                  VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                  VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR);
    fn.cmdBuild(cmd, 1, &b, &ranges);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                  VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
                  VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
}

} // namespace shadel
