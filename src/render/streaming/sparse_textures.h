#pragma once
// The GPU side of sparse residency (--streaming sparse): one sparse-resident image per texture
// (its whole MIP chain as address space), its MIP tail bound at creation from one tail
// allocation (the device's packed tail opaquely; before it, the levels smaller than a page, which
// a device without a packed tail such as lavapipe pages like any other), and a fixed pool of pages
// (sparse blocks of 64 KiB: 128^2 RGBA8 or 256^2 BC7 texels) that level loads bind into and
// evictions unbind from, with vkQueueBindSparse. The bookkeeping of who holds which page is
// sparse_residency.h.
//
// Binds are queued before the frame and signal a semaphore the frame's first submission waits on
// (binds are not ordered against command buffers otherwise). Unbinds are safe then too: the
// previous frame has finished when the next is prepared (the frame recorder waits), so nothing
// still reads a level whose pages go.
#include <cstdint>
#include <string>
#include <vector>

#include "bake/block_compression/block_compression.h"
#include "render/streaming/sparse_residency.h"
#include "rhi/vk.h"

namespace shadel {

struct Gpu;

struct SparseImage {
    VkImage image = VK_NULL_HANDLE;
    std::vector<VkImageView> views; // per base level 0..tailFirst: that level and coarser
    uint32_t levels = 0;
    uint32_t deviceTailFirst = 0; // the device's packed MIP tail (== levels: it has none)
};

struct SparseTextures {
    Gpu* gpu = nullptr;
    BlockFormat format = BlockFormat::Rgba8;
    std::vector<SparseImage> images;
    VkExtent3D granularity{}; // texels per page (blocks times the block side for BC formats)
    uint64_t pageBytes = 0;
    uint32_t memoryType = 0;
    VkDeviceMemory tailMemory = VK_NULL_HANDLE, poolMemory = VK_NULL_HANDLE;
    uint64_t tailBytes = 0, poolBytes = 0; // what is allocated: all the textures ever use
    VkSemaphore bound = VK_NULL_HANDLE;    // signalled by this frame's binds
    SparseResidency residency;
    uint64_t pageBinds = 0, pageUnbinds = 0;
};

// The Vulkan format of a streamed texture's blocks, read as sRGB or linear.
VkFormat packedVkFormat(BlockFormat format, bool srgb);

// Empty when the device can page 2-D images of the format (features, queue), else why not.
std::string sparseUnsupportedReason(const Gpu& gpu, BlockFormat format);

// Images for textures of the given sides (power of two, sRGB or linear, all of one format), their
// tails bound (not yet uploaded: levels tailFirst.. are UNDEFINED), and a pool of the pages the
// budget has left after the tails. Throws InputError when the tails alone exceed budgetBytes.
void createSparseTextures(Gpu& gpu, const std::vector<uint32_t>& sizes,
                          const std::vector<bool>& srgb, BlockFormat format, uint64_t budgetBytes,
                          SparseTextures& out);
void destroySparseTextures(SparseTextures& s);

// The view a texture is sampled through: its resident level and coarser.
VkImageView sparseResidentView(const SparseTextures& s, uint32_t texture);

// Queues the binds of landed loads and the unbinds of evictions; returns the semaphore the
// frame's first submission must wait on (null when there was nothing to bind).
VkSemaphore submitSparseBinds(SparseTextures& s, const std::vector<const SparseLevelLoad*>& binds,
                              const std::vector<SparseEviction>& unbinds);

} // namespace shadel
