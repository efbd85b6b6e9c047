#include "render/streaming/texture_cache.h"

#include <algorithm>
#include <numeric>

#include "core/assert.h"
#include "core/error.h"
#include "core/log.h"

namespace shadel {

TextureCache makeTextureCache(const std::vector<uint32_t>& textureSizes, uint64_t budgetBytes,
                              const std::function<uint64_t(uint32_t)>& bytesOf) {
    TextureCache cache;
    uint32_t largest = 0;
    for (uint32_t s : textureSizes) {
        cache.textures.push_back({s});
        cache.tailBytes += bytesOf(std::min(s, kTailSize));
        largest = std::max(largest, s);
    }
    if (cache.tailBytes > budgetBytes)
        throw InputError(format("--texture-budget %.2f: below the %.2f MiB the %zu textures' "
                                "resident MIP tails (%u^2) need",
                                double(budgetBytes) / 1048576.0,
                                double(cache.tailBytes) / 1048576.0, textureSizes.size(),
                                kTailSize));
    for (uint32_t size = kTailSize * 2; size <= largest; size *= 2) {
        CacheLayer layer;
        layer.size = size;
        layer.slotBytes = bytesOf(size);
        cache.layers.push_back(layer);
    }
    const size_t L = cache.layers.size();
    auto eligible = [&](size_t k) {
        return uint32_t(std::count_if(textureSizes.begin(), textureSizes.end(),
                                      [&](uint32_t s) { return s >= cache.layers[k].size; }));
    };
    std::vector<uint32_t> count(L, 0);
    uint64_t left = budgetBytes - cache.tailBytes;
    uint32_t slotsLeft = uint32_t(textureSizes.size()); // no texture needs two slots
    for (size_t k = L; k-- > 0;) {
        uint64_t share = left / (k + 1);
        uint32_t n = uint32_t(std::min<uint64_t>(share / cache.layers[k].slotBytes,
                                                 std::min(eligible(k), slotsLeft)));
        count[k] = n;
        left -= uint64_t(n) * cache.layers[k].slotBytes;
        slotsLeft -= n;
    }
    // What is left: more large slots, each replacing the smallest slot when slots run out.
    for (size_t k = L; k-- > 0;) {
        for (;;) {
            if (count[k] >= eligible(k)) break;
            uint64_t refund = 0;
            size_t smallest = L;
            if (slotsLeft == 0) {
                for (size_t j = 0; j < k; ++j)
                    if (count[j] > 0) {
                        smallest = j;
                        break;
                    }
                if (smallest == L) break;
                refund = cache.layers[smallest].slotBytes;
            }
            if (left + refund < cache.layers[k].slotBytes) break;
            left = left + refund - cache.layers[k].slotBytes;
            count[k]++;
            if (smallest != L)
                count[smallest]--;
            else
                slotsLeft--;
        }
    }
    cache.allocatedBytes = cache.tailBytes;
    for (size_t k = 0; k < L; ++k) {
        cache.layers[k].owner.assign(count[k], -1);
        cache.layers[k].reserved.assign(count[k], false);
        cache.allocatedBytes += uint64_t(count[k]) * cache.layers[k].slotBytes;
    }
    SHADEL_ASSERT(cache.allocatedBytes <= budgetBytes);
    return cache;
}

int32_t targetLayer(const TextureCache& cache, const CachedTexture& t) {
    float want = std::min(t.wanted, float(t.size));
    int32_t target = -1;
    for (size_t k = 0; k < cache.layers.size(); ++k) {
        if (cache.layers[k].size > t.size) break;
        target = int32_t(k);
        if (float(cache.layers[k].size) >= want) break; // the smallest layer that holds it
    }
    if (want <= float(kTailSize)) return -1;
    return target;
}

std::vector<CacheExchange> planExchanges(TextureCache& cache, const TextureCacheLimits& limits) {
    std::vector<CacheExchange> out;
    std::vector<int32_t> order(cache.textures.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int32_t a, int32_t b) {
        return cache.textures[a].wanted > cache.textures[b].wanted;
    });
    for (int32_t c : order) {
        if (cache.pending >= limits.pendingTotal) break;
        CachedTexture& tex = cache.textures[c];
        if (tex.pending || tex.failedLoads >= 3) continue;
        int32_t target = targetLayer(cache, tex);
        for (int32_t k = target; k > tex.layer; --k) {
            CacheLayer& layer = cache.layers[k];
            if (layer.pending >= limits.pendingPerLayer || layer.owner.empty()) continue;
            int32_t chosen = -1, victim = -1;
            for (size_t s = 0; s < layer.owner.size() && chosen < 0; ++s)
                if (layer.owner[s] < 0 && !layer.reserved[s]) chosen = int32_t(s);
            if (chosen < 0) { // the lowest priority occupant that yields
                float lowest = 0.0f;
                for (size_t s = 0; s < layer.owner.size(); ++s) {
                    if (layer.reserved[s]) continue;
                    const CachedTexture& v = cache.textures[layer.owner[s]];
                    if (v.pending) continue;
                    bool needsIt = targetLayer(cache, v) >= k;
                    bool yields =
                        needsIt ? v.wanted * limits.swapRatio < tex.wanted : v.wanted < tex.wanted;
                    if (yields && (chosen < 0 || v.wanted < lowest))
                        chosen = int32_t(s), victim = layer.owner[s], lowest = v.wanted;
                }
            }
            if (chosen < 0) continue; // try a smaller layer
            CacheExchange e{c, tex.layer, tex.slot, k, chosen, victim};
            tex.pending = true;
            if (victim >= 0) cache.textures[victim].pending = true;
            layer.reserved[chosen] = true;
            layer.pending++;
            cache.pending++;
            out.push_back(e);
            break;
        }
    }
    return out;
}

static void endExchange(TextureCache& cache, const CacheExchange& e) {
    CacheLayer& layer = cache.layers[e.toLayer];
    layer.reserved[e.toSlot] = false;
    layer.pending--;
    cache.pending--;
    cache.textures[e.texture].pending = false;
    if (e.victim >= 0) cache.textures[e.victim].pending = false;
}

void commitExchange(TextureCache& cache, const CacheExchange& e) {
    endExchange(cache, e);
    CachedTexture& tex = cache.textures[e.texture];
    cache.layers[e.toLayer].owner[e.toSlot] = e.texture;
    tex.layer = e.toLayer, tex.slot = e.toSlot;
    if (e.victim >= 0) {
        CachedTexture& v = cache.textures[e.victim];
        v.layer = e.fromLayer, v.slot = e.fromSlot;
        if (e.fromLayer >= 0) cache.layers[e.fromLayer].owner[e.fromSlot] = e.victim;
    } else if (e.fromLayer >= 0) {
        cache.layers[e.fromLayer].owner[e.fromSlot] = -1;
    }
}

void abandonExchange(TextureCache& cache, const CacheExchange& e) {
    endExchange(cache, e);
    cache.textures[e.texture].failedLoads++;
}

uint64_t residentBytes(const TextureCache& cache) {
    uint64_t bytes = cache.tailBytes;
    for (const CacheLayer& l : cache.layers)
        for (int32_t o : l.owner) bytes += o >= 0 ? l.slotBytes : 0;
    return bytes;
}

uint32_t residentSize(const TextureCache& cache, const CachedTexture& t) {
    return t.layer >= 0 ? cache.layers[t.layer].size : std::min(t.size, kTailSize);
}

} // namespace shadel
