#include "render/streaming/sparse_residency.h"

#include <algorithm>
#include <numeric>

#include "core/assert.h"

namespace shadel {

SparseResidency makeSparseResidency(std::vector<SparseTexture> textures, uint32_t poolPages) {
    SparseResidency r;
    uint64_t everything = 0;
    for (SparseTexture& t : textures) {
        SHADEL_ASSERT(t.levelPages.size() == t.tailFirst);
        t.resident = t.tailFirst;
        t.pages.assign(t.tailFirst, {});
        for (uint32_t p : t.levelPages) everything += p;
    }
    r.textures = std::move(textures);
    r.poolPages = uint32_t(std::min<uint64_t>(poolPages, everything));
    r.freePages.resize(r.poolPages);
    // Handed out from the back: page 0 first.
    std::iota(r.freePages.rbegin(), r.freePages.rend(), 0u);
    return r;
}

uint32_t sparseTargetLevel(const SparseTexture& t) {
    float want = std::min(t.wanted, float(t.size));
    uint32_t level = t.tailFirst;
    // The coarsest level whose side still holds the wish.
    while (level > 0 && float(t.size >> level) < want) --level;
    return level;
}

uint32_t usedPages(const SparseResidency& r) {
    return r.poolPages - uint32_t(r.freePages.size());
}

uint32_t residentPages(const SparseResidency& r) {
    uint32_t n = 0;
    for (const SparseTexture& t : r.textures)
        for (const auto& level : t.pages) n += uint32_t(level.size());
    return n;
}

// Frees at least `need` pages by evicting finest levels, or evicts nothing and returns false.
// Who yields: first those holding more than they want (any priority), then much lower priorities
// than `wanted`; lowest priority first in each group, one level each.
static bool makeRoom(SparseResidency& r, int32_t requester, float wanted, uint64_t need,
                     const TextureCacheLimits& limits, std::vector<SparseEviction>& evictions) {
    if (r.freePages.size() >= need) return true;
    std::vector<int32_t> victims;
    for (size_t v = 0; v < r.textures.size(); ++v) {
        const SparseTexture& o = r.textures[v];
        if (int32_t(v) == requester || o.pending || o.resident >= o.tailFirst ||
            o.changedFrame == r.frame)
            continue;
        bool surplus = sparseTargetLevel(o) > o.resident;
        if (surplus || o.wanted * limits.swapRatio < wanted) victims.push_back(int32_t(v));
    }
    std::stable_sort(victims.begin(), victims.end(), [&](int32_t a, int32_t b) {
        const SparseTexture &ta = r.textures[a], &tb = r.textures[b];
        bool sa = sparseTargetLevel(ta) > ta.resident;
        bool sb = sparseTargetLevel(tb) > tb.resident;
        if (sa != sb) return sa;
        return ta.wanted < tb.wanted;
    });
    size_t count = 0;
    uint64_t freed = r.freePages.size();
    while (count < victims.size() && freed < need) {
        const SparseTexture& o = r.textures[victims[count]];
        freed += o.levelPages[o.resident];
        ++count;
    }
    if (freed < need) return false; // no eviction for nothing
    for (size_t k = 0; k < count; ++k) {
        SparseTexture& o = r.textures[victims[k]];
        SparseEviction e{victims[k], o.resident, std::move(o.pages[o.resident])};
        o.pages[o.resident].clear();
        for (uint32_t p : e.pages) r.freePages.push_back(p);
        o.resident++;
        o.changedFrame = r.frame;
        evictions.push_back(std::move(e));
    }
    return true;
}

void planSparseLoads(SparseResidency& r, const TextureCacheLimits& limits, uint64_t maxLoadPages,
                     std::vector<SparseLevelLoad>& loads, std::vector<SparseEviction>& evictions) {
    std::vector<int32_t> order(r.textures.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int32_t a, int32_t b) {
        return r.textures[a].wanted > r.textures[b].wanted;
    });
    for (int32_t c : order) {
        if (r.pending >= limits.pendingTotal) break;
        SparseTexture& tex = r.textures[c];
        if (tex.pending || tex.failedLoads >= 3 || tex.resident == 0 || tex.changedFrame == r.frame)
            continue;
        // Every level down to the target in one load (as the layered path fills a slot of the
        // target size at once); when the pool cannot make room for that, fewer levels.
        for (uint32_t first = sparseTargetLevel(tex); first < tex.resident; ++first) {
            uint64_t need = 0;
            for (uint32_t l = first; l < tex.resident; ++l) need += tex.levelPages[l];
            if (need > r.poolPages || need > maxLoadPages ||
                !makeRoom(r, c, tex.wanted, need, limits, evictions))
                continue;
            SparseLevelLoad load{c, first, tex.resident - first, {}};
            for (uint64_t i = 0; i < need; ++i) {
                load.pages.push_back(r.freePages.back());
                r.freePages.pop_back();
            }
            tex.pending = true;
            r.pending++;
            loads.push_back(std::move(load));
            break;
        }
    }
}

void commitSparseLoad(SparseResidency& r, const SparseLevelLoad& load) {
    SparseTexture& t = r.textures[load.texture];
    SHADEL_ASSERT(t.pending && load.level + load.levels == t.resident);
    t.pending = false;
    r.pending--;
    size_t k = 0;
    for (uint32_t l = load.level; l < t.resident; ++l) {
        t.pages[l].assign(load.pages.begin() + k, load.pages.begin() + k + t.levelPages[l]);
        k += t.levelPages[l];
    }
    SHADEL_ASSERT(k == load.pages.size());
    t.resident = load.level;
    t.changedFrame = r.frame;
}

void abandonSparseLoad(SparseResidency& r, const SparseLevelLoad& load) {
    SparseTexture& t = r.textures[load.texture];
    t.pending = false;
    r.pending--;
    t.failedLoads++;
    for (uint32_t p : load.pages) r.freePages.push_back(p);
}

} // namespace shadel
