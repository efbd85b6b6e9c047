#pragma once
// The 3-D atlas of mesh distance fields: every resident field gets a box of voxels in
// one atlas volume from the 3-D block allocator (core/block_allocator.h); fields are added and
// removed as meshes come and go (streaming), and freed room is reused. Only the bookkeeping
// lives here (CPU); render/distance_fields/distance_fields.* owns the GPU copy.
#include <cstdint>
#include <optional>
#include <unordered_map>

#include "core/block_allocator.h"

namespace shadel {

class DistanceFieldAtlas {
public:
    explicit DistanceFieldAtlas(Extent<3> size) : m_allocator(size) {}

    // Reserves a box for the field of `key` (a mesh); nullopt when the atlas has no room (the
    // mesh then casts no distance-field shadow). Adding a key twice returns its box.
    std::optional<Placement<3>> add(uint32_t key, Extent<3> voxels) {
        if (auto it = m_boxes.find(key); it != m_boxes.end()) return it->second;
        std::optional<Placement<3>> p = m_allocator.insert(voxels);
        if (p) m_boxes.emplace(key, *p);
        return p;
    }
    // Frees the box of `key`; false if it had none.
    bool remove(uint32_t key) {
        auto it = m_boxes.find(key);
        if (it == m_boxes.end()) return false;
        m_allocator.remove(it->second.id);
        m_boxes.erase(it);
        return true;
    }
    std::optional<Placement<3>> find(uint32_t key) const {
        auto it = m_boxes.find(key);
        if (it == m_boxes.end()) return std::nullopt;
        return it->second;
    }
    const std::unordered_map<uint32_t, Placement<3>>& boxes() const { return m_boxes; }
    Extent<3> size() const { return m_allocator.bounds(); }
    uint64_t usedVoxels() const { return m_allocator.usedVolume(); }
    bool validate() const { return m_allocator.validate(); }

private:
    BlockAllocator<3> m_allocator;
    std::unordered_map<uint32_t, Placement<3>> m_boxes;
};

} // namespace shadel
