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

void planSparseLoads(SparseResidency& r, const TextureCacheLimits& limits,
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
        if (sparseTargetLevel(tex) >= tex.resident) continue;
        uint32_t level = tex.resident - 1;
        uint32_t need = tex.levelPages[level];
        if (need > r.poolPages) continue;
        if (r.freePages.size() < need) {
            // Who yields its finest level: first those holding more than they want (any
            // priority), then much lower priorities; lowest priority first in each group.
            std::vector<int32_t> victims;
            for (size_t v = 0; v < r.textures.size(); ++v) {
                const SparseTexture& o = r.textures[v];
                if (int32_t(v) == c || o.pending || o.resident >= o.tailFirst ||
                    o.changedFrame == r.frame)
                    continue;
                bool surplus = sparseTargetLevel(o) > o.resident;
                if (surplus || o.wanted * limits.swapRatio < tex.wanted)
                    victims.push_back(int32_t(v));
            }
            std::stable_sort(victims.begin(), victims.end(), [&](int32_t a, int32_t b) {
                const SparseTexture &ta = r.textures[a], &tb = r.textures[b];
                bool sa = sparseTargetLevel(ta) > ta.resident;
                bool sb = sparseTargetLevel(tb) > tb.resident;
                if (sa != sb) return sa;
                return ta.wanted < tb.wanted;
            });
            // Only evict when the victims together free enough (no eviction for nothing).
            size_t count = 0;
            uint64_t freed = r.freePages.size();
            while (count < victims.size() && freed < need) {
                const SparseTexture& o = r.textures[victims[count]];
                freed += o.levelPages[o.resident];
                ++count;
            }
            if (freed < need) continue;
            for (size_t k = 0; k < count; ++k) {
                SparseTexture& o = r.textures[victims[k]];
                SparseEviction e{victims[k], o.resident, std::move(o.pages[o.resident])};
                o.pages[o.resident].clear();
                for (uint32_t p : e.pages) r.freePages.push_back(p);
                o.resident++;
                o.changedFrame = r.frame;
                evictions.push_back(std::move(e));
            }
        }
        SparseLevelLoad load{c, level, {}};
        for (uint32_t i = 0; i < need; ++i) {
            load.pages.push_back(r.freePages.back());
            r.freePages.pop_back();
        }
        tex.pending = true;
        r.pending++;
        loads.push_back(std::move(load));
    }
}

void commitSparseLoad(SparseResidency& r, const SparseLevelLoad& load) {
    SparseTexture& t = r.textures[load.texture];
    SHADEL_ASSERT(t.pending && load.level + 1 == t.resident);
    t.pending = false;
    r.pending--;
    t.pages[load.level] = load.pages;
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
