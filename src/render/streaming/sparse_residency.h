#pragma once
// Sparse residency's bookkeeping (--streaming sparse), CPU only: which MIP levels of which texture
// hold pages of the fixed page pool, and which level loads to start this frame. The GPU side
// (sparse_textures.h) owns the sparse images and the pool's memory and carries the binds out.
//
// The same cache logic as the layered path (texture_cache.h) with pages instead of slots: each
// texture wants a side (the merged CPU + GPU priority); its target level is the coarsest whose
// side holds that. The levels from there to the resident one come in as one load (fewer when the
// pool cannot make room for all), whose pages are taken from the pool when it is planned; when the
// pool is short, textures holding more than they want, then much lower priorities, give back their
// finest level (pairwise, by priority, with the layered path's swap ratio). Every texture's MIP
// tail (levels from tailFirst on, as the device packs them, and the levels smaller than a page) is
// bound once at creation and never paged. The pool's size is fixed from the budget, so bound memory
// never exceeds it by construction.
//
// Shaders never see a level that is not whole: a texture is sampled through a view starting at
// its resident level, which moves only when a level's every page is bound and copied.
#include <cstdint>
#include <vector>

#include "render/streaming/texture_cache.h"

namespace shadel {

struct SparseTexture {
    uint32_t size = 0;                // level 0 side (power of two)
    uint32_t tailFirst = 0;           // first level of the MIP tail (always bound)
    std::vector<uint32_t> levelPages; // per level below tailFirst: pages (sparse blocks) it takes
    uint32_t resident = 0;            // finest whole level (the sampled view's base)
    std::vector<std::vector<uint32_t>> pages; // per level below tailFirst: pool pages bound
    bool pending = false;                     // a level load in flight
    uint64_t changedFrame = ~0ull;            // a level came or went this frame: cannot yield now
    float wanted = 0.0f;                      // merged priority: the side it wants
    uint32_t failedLoads = 0;
};

// A load of levels [level, level + levels) (down to the texture's resident level): `pages` (pool
// indices: per level from the finest, one per block in row-major block order) are reserved until
// the load lands (commit: bind + copy) or fails.
struct SparseLevelLoad {
    int32_t texture = -1;
    uint32_t level = 0, levels = 1;
    std::vector<uint32_t> pages;
};

// A level given back: its pages are unbound this frame and free for others.
struct SparseEviction {
    int32_t texture = -1;
    uint32_t level = 0;
    std::vector<uint32_t> pages;
};

struct SparseResidency {
    std::vector<SparseTexture> textures;
    uint32_t poolPages = 0;
    std::vector<uint32_t> freePages;
    uint32_t pending = 0;
    uint64_t frame = 0; // counts beginSparseFrame calls
};

// poolPages from the budget left after the tails, at most what every level of every texture
// would take (the pool never holds pages nobody could use).
SparseResidency makeSparseResidency(std::vector<SparseTexture> textures, uint32_t poolPages);

// The level a texture wanting `wanted` texels across should have resident.
uint32_t sparseTargetLevel(const SparseTexture& t);
// Pool pages in use: bound to resident levels, or reserved for loads in flight.
uint32_t usedPages(const SparseResidency& r);
// Pool pages bound to resident levels.
uint32_t residentPages(const SparseResidency& r);

// Starts a frame: levels that change in it (commits, evictions) cannot change again until the
// next, so one frame's binds never bind and unbind the same range.
inline void beginSparseFrame(SparseResidency& r) {
    r.frame++;
}

// This frame's loads by priority (pages reserved, textures marked pending) and the evictions that
// made room (applied at once: the texture's resident level is already coarser). No load takes
// more than maxLoadPages (what the staging ring can hold).
void planSparseLoads(SparseResidency& r, const TextureCacheLimits& limits, uint64_t maxLoadPages,
                     std::vector<SparseLevelLoad>& loads, std::vector<SparseEviction>& evictions);
// A landed load: its level becomes resident. A failed one: its pages go back.
void commitSparseLoad(SparseResidency& r, const SparseLevelLoad& load);
void abandonSparseLoad(SparseResidency& r, const SparseLevelLoad& load);

} // namespace shadel
