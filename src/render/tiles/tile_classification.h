#pragma once
// Tile classification: the screen is cut into 8x8 tiles, classified once per frame
// from the thin G-buffer's pixel flags (one subgroup per tile: subgroup OR / AND), and each tile is
// appended to the list of every screen-space permutation it needs (TILE_LIST_* in
// shaders/tiles/tile_types.h), with the indirect dispatch arguments of each list. Passes then
// dispatch over their lists (dispatchTileList) instead of the whole screen (dispatchAllTiles).
#include <array>
#include <cstdint>

#include "rhi/handles.h"
#include "rhi/pipeline.h"
#include "tiles/tile_types.h"

namespace shadel {

struct Gpu;

struct TileClassification {
    uint32_t tilesX = 0, tilesY = 0;
    uint32_t classifyGroups = 0; // workgroups of the classification (a tile per subgroup)
    BufferHandle buffer;         // TileBufferHeader, the lists, a class mask per tile
    BufferHandle readback;       // the last frame's list counts (stats)
    Pipeline classify, visualize;
    std::array<uint32_t, TILE_LIST_COUNT> counts{}; // read back after the frame
};

TileClassification createTileClassification(Gpu& gpu, uint32_t width, uint32_t height);
void destroyTileClassification(Gpu& gpu, TileClassification& t);

// Resets the lists and classifies every tile; `push` is the screen-space passes' push constants
// (gpu::ScreenSpacePush: the G-buffer flags slot, the size). Leaves the lists readable by
// compute shaders and indirect dispatch.
template <typename Push>
void recordTileClassification(Gpu& gpu, VkCommandBuffer cmd, TileClassification& t, Push push);
// The first entry of a list in the buffer (ScreenSpacePush::listOffset).
uint32_t tileListOffset(const TileClassification& t, uint32_t list);
// One workgroup per tile of the list (its count, from the GPU's arguments).
void dispatchTileList(Gpu& gpu, VkCommandBuffer cmd, const TileClassification& t, uint32_t list);
// One workgroup per tile of the screen (classification off).
void dispatchAllTiles(VkCommandBuffer cmd, const TileClassification& t);
// Copies the list counts for readTileCounts (after the frame's last use of the lists).
void recordTileCountReadback(Gpu& gpu, VkCommandBuffer cmd, TileClassification& t);
void readTileCounts(Gpu& gpu, TileClassification& t);
const char* tileListName(uint32_t list);

} // namespace shadel
