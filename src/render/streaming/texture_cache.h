#pragma once
// The layered texture cache's bookkeeping, CPU only: which texture sits in which slot
// of which layer, and which pairwise exchanges to start this frame. The GPU side
// (texture_streaming.h) owns the images and carries the exchanges out.
//
// Layers hold slots of one fixed size each (64^2 tails, then 128^2, 256^2, ... up to the largest
// texture), every slot an image with that size's full MIP chain. Every texture's MIP tail (its
// levels up to kTailSize) is always resident, so a texture with no slot still draws. Slot counts
// are fixed when the cache is made, from the budget: the cache never allocates later, so its
// memory is what it allocated at the start, and that is within the budget by construction.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace shadel {

constexpr uint32_t kTailSize = 64;

struct CacheLayer {
    uint32_t size = 0;          // slot side in texels
    uint64_t slotBytes = 0;     // one slot image's memory
    std::vector<int32_t> owner; // per slot: texture index, -1 = free
    std::vector<bool> reserved; // per slot: an exchange into it is in flight
    uint32_t pending = 0;       // exchanges in flight into this layer
};

struct CachedTexture {
    uint32_t size = 0;  // full resolution side (power of two)
    int32_t layer = -1; // -1: only its tail is resident
    int32_t slot = -1;
    bool pending = false; // in an exchange in flight (cannot be chosen again until it lands)
    float wanted = 0.0f;  // the resolution it wants (texels across), the merged priority
    uint32_t failedLoads = 0;
};

// One pairwise exchange: `texture` moves up into (toLayer, toSlot); `victim` (if >= 0), the
// slot's owner, moves down into the slot `texture` leaves (fromLayer, fromSlot; -1 = its tail).
struct CacheExchange {
    int32_t texture = -1;
    int32_t fromLayer = -1, fromSlot = -1;
    int32_t toLayer = -1, toSlot = -1;
    int32_t victim = -1;
};

struct TextureCacheLimits {
    uint32_t pendingPerLayer = 4; // exchanges in flight into one layer (I/O throughput)
    uint32_t pendingTotal = 8;
    float swapRatio =
        1.5f; // a texture that wants its layer too yields only to a much higher priority
};

struct TextureCache {
    std::vector<CacheLayer> layers; // increasing size
    std::vector<CachedTexture> textures;
    uint64_t tailBytes = 0;      // every texture's resident tail
    uint64_t allocatedBytes = 0; // tails + every slot: the cache's whole memory
    uint32_t pending = 0;
};

// Plans the layers for textures of the given sides within budgetBytes; bytesOf(side) is one
// image of that side with its full MIP chain as the device allocates it. Equal shares of the
// budget per layer from the largest down, then what is left buys more large slots (each taking
// the place of a small one, since no texture needs two slots). Throws InputError when the tails
// alone do not fit.
TextureCache makeTextureCache(const std::vector<uint32_t>& textureSizes, uint64_t budgetBytes,
                              const std::function<uint64_t(uint32_t)>& bytesOf);

// The layer a texture wanting `wanted` texels across should sit in (-1: its tail suffices).
int32_t targetLayer(const TextureCache& cache, const CachedTexture& texture);

// Chooses this frame's exchanges by priority (marks them pending and their slots reserved).
std::vector<CacheExchange> planExchanges(TextureCache& cache, const TextureCacheLimits& limits);
// Applies a landed exchange (ownership moves), or abandons a failed one.
void commitExchange(TextureCache& cache, const CacheExchange& e);
void abandonExchange(TextureCache& cache, const CacheExchange& e);

// Memory of the occupied slots plus the tails (what the cache's contents need right now).
uint64_t residentBytes(const TextureCache& cache);
// The side a texture is sampled at now.
uint32_t residentSize(const TextureCache& cache, const CachedTexture& texture);

} // namespace shadel
