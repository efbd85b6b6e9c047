#include "render/tiles/tile_classification.h"

#include <algorithm>
#include <cstring>

#include "core/error.h"
#include "rhi/gpu.h"
#include "screenspace/screen_space_types.h"

namespace shadel {

namespace {
VkDeviceSize listBytes(const TileClassification& t) {
    VkDeviceSize tiles = VkDeviceSize(t.tilesX) * t.tilesY;
    return sizeof(gpu::TileBufferHeader) + (TILE_LIST_COUNT + 1) * tiles * sizeof(uint32_t);
}

// How many tiles a 64-invocation classification workgroup covers: one per subgroup, counted
// with the largest subgroup size the device may use (SPIR-V 1.6 lets it vary), so the dispatch
// always reaches every tile; 64 (one per invocation) without subgroup OR / AND in compute
// (Vulkan 1.1 makes them optional).
uint32_t tilesPerClassifyGroup(const Gpu& gpu) {
    VkPhysicalDeviceVulkan13Properties v13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_PROPERTIES};
    VkPhysicalDeviceSubgroupProperties subgroup{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
    subgroup.pNext = &v13;
    VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    props.pNext = &subgroup;
    vkGetPhysicalDeviceProperties2(gpu.device.physical, &props);
    bool arithmetic = (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) &&
                      (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT) &&
                      (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_BASIC_BIT);
    if (!arithmetic) return 64;
    uint32_t largest = std::max({subgroup.subgroupSize, v13.maxSubgroupSize, 1u});
    return std::max(64u / largest, 1u);
}
} // namespace

TileClassification createTileClassification(Gpu& gpu, uint32_t width, uint32_t height) {
    TileClassification t;
    t.tilesX = (width + TILE_SIZE - 1) / TILE_SIZE;
    t.tilesY = (height + TILE_SIZE - 1) / TILE_SIZE;
    t.buffer =
        createBuffer(gpu, {"tiles.lists", listBytes(t),
                           VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                               VK_BUFFER_USAGE_TRANSFER_SRC_BIT});
    t.readback = createBuffer(gpu, {"tiles.counts.readback", sizeof(gpu::TileBufferHeader),
                                    VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryKind::Readback});
    if (!t.buffer || !t.readback) throw DeviceError("out of GPU memory for the tile lists");
    uint32_t perGroup = tilesPerClassifyGroup(gpu);
    t.classifyGroups = (t.tilesX * t.tilesY + perGroup - 1) / perGroup;
    t.classify = createComputePipeline(gpu, "tileClassify", "tiles_classify.comp.spv",
                                       {{0, perGroup == 64 ? 0u : 1u}});
    t.visualize = createComputePipeline(gpu, "tileVisualize", "tiles_visualize.comp.spv");
    return t;
}

void destroyTileClassification(Gpu& gpu, TileClassification& t) {
    destroy(gpu, t.classify);
    destroy(gpu, t.visualize);
    if (t.buffer) destroy(gpu, t.buffer);
    if (t.readback) destroy(gpu, t.readback);
    t = {};
}

template <typename Push>
void recordTileClassification(Gpu& gpu, VkCommandBuffer cmd, TileClassification& t, Push push) {
    // Every list empty, dispatched as (count, 1, 1).
    gpu::TileBufferHeader header{};
    for (auto& a : header.args) a = {0, 1, 1};
    memoryBarrier(cmd,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT |
                      VK_PIPELINE_STAGE_2_COPY_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT |
                      VK_ACCESS_2_TRANSFER_READ_BIT,
                  VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    vkCmdUpdateBuffer(cmd, vkBuffer(gpu, t.buffer), 0, sizeof(header), &header);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    push.tiles = address(gpu, t.buffer);
    push.tilesX = t.tilesX;
    bind(gpu, cmd, t.classify);
    pushConstants(gpu, cmd, push);
    vkCmdDispatch(cmd, t.classifyGroups, 1, 1);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
}
template void recordTileClassification<gpu::ScreenSpacePush>(Gpu&, VkCommandBuffer,
                                                             TileClassification&,
                                                             gpu::ScreenSpacePush);

uint32_t tileListOffset(const TileClassification& t, uint32_t list) {
    return list * t.tilesX * t.tilesY;
}

void dispatchTileList(Gpu& gpu, VkCommandBuffer cmd, const TileClassification& t, uint32_t list) {
    vkCmdDispatchIndirect(cmd, vkBuffer(gpu, t.buffer), list * sizeof(gpu::TileDispatch));
}

void dispatchAllTiles(VkCommandBuffer cmd, const TileClassification& t) {
    vkCmdDispatch(cmd, t.tilesX, t.tilesY, 1);
}

void recordTileCountReadback(Gpu& gpu, VkCommandBuffer cmd, TileClassification& t) {
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    VkBufferCopy copy{0, 0, sizeof(gpu::TileBufferHeader)};
    vkCmdCopyBuffer(cmd, vkBuffer(gpu, t.buffer), vkBuffer(gpu, t.readback), 1, &copy);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
}

void readTileCounts(Gpu& gpu, TileClassification& t) {
    gpu::TileBufferHeader header;
    std::memcpy(&header, mapped(gpu, t.readback), sizeof(header));
    for (uint32_t i = 0; i < TILE_LIST_COUNT; ++i) t.counts[i] = header.args[i].x;
}

const char* tileListName(uint32_t list) {
    switch (list) {
    case TILE_LIST_SKY:
        return "sky";
    case TILE_LIST_SKY_EDGE:
        return "sky_edge";
    case TILE_LIST_SURFACE:
        return "surface";
    case TILE_LIST_SSR:
        return "ssr";
    case TILE_LIST_SSR_CLEAR:
        return "ssr_clear";
    case TILE_LIST_SSS:
        return "sss";
    default:
        return "?";
    }
}

} // namespace shadel
