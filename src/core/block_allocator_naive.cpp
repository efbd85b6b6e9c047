#include "core/block_allocator_naive.h"

#include <algorithm>

#include "core/assert.h"

namespace shadel {

using block_detail::fitsIn;
using block_detail::volume;

template <size_t N>
NaiveBlockAllocator<N>::NaiveBlockAllocator(Extent<N> size, uint32_t alignment)
    : m_bounds(size), m_alignment(alignment < 1 ? 1 : alignment) {
    clear();
}

template <size_t N>
void NaiveBlockAllocator<N>::clear() {
    m_nodes.clear();
    Node root;
    for (size_t axis = 0; axis < N; ++axis)
        root.size[axis] = m_bounds[axis] / m_alignment * m_alignment;
    m_nodes.push_back(root);
    // Same id policy as BlockAllocator (lowest free slot first after clear, then LIFO), so that
    // differential tests can compare ids too.
    m_freeSlots.clear();
    for (uint32_t slot = 0; slot < m_slotLive.size(); ++slot) {
        if (m_slotLive[slot]) ++m_slotGeneration[slot];
        m_slotLive[slot] = false;
    }
    for (uint32_t slot = uint32_t(m_slotLive.size()); slot-- > 0;) m_freeSlots.push_back(slot);
    m_liveCount = 0;
    m_usedVolume = 0;
}

template <size_t N>
NaiveBlockAllocator<N>
NaiveBlockAllocator<N>::fromPreorder(Extent<N> size, uint32_t alignment,
                                     std::span<const BlockTreeNode<N>> nodes) {
    NaiveBlockAllocator out(size, alignment);
    out.m_nodes.clear();
    uint32_t slots = 0;
    for (const auto& entry : nodes)
        if (entry.used) slots = std::max(slots, entry.id.slot + 1);
    out.m_slotGeneration.assign(slots, 0);
    out.m_slotLive.assign(slots, false);
    // In preorder a node's child A follows it directly and child B follows A's subtree; the
    // stack holds inner nodes still waiting for child B.
    std::vector<int32_t> waitingForB;
    for (const auto& entry : nodes) {
        int32_t index = int32_t(out.m_nodes.size());
        Node node;
        node.min = entry.min;
        node.size = entry.size;
        node.used = entry.used;
        node.id = entry.id;
        out.m_nodes.push_back(node);
        if (index > 0) {
            Node& parent = out.m_nodes[index - 1];
            if (!nodes[index - 1].leaf && parent.childA == kNone) {
                parent.childA = index;
            } else {
                SHADEL_ASSERT(!waitingForB.empty());
                out.m_nodes[waitingForB.back()].childB = index;
                waitingForB.pop_back();
            }
        }
        if (!entry.leaf) waitingForB.push_back(index);
        if (entry.used) {
            out.m_slotLive[entry.id.slot] = true;
            out.m_slotGeneration[entry.id.slot] = entry.id.generation;
            ++out.m_liveCount;
            out.m_usedVolume += volume<N>(entry.size);
        }
    }
    SHADEL_ASSERT(waitingForB.empty());
    out.m_freeSlots.clear();
    for (uint32_t slot = slots; slot-- > 0;)
        if (!out.m_slotLive[slot]) out.m_freeSlots.push_back(slot);
    return out;
}

template <size_t N>
BlockId NaiveBlockAllocator<N>::newId() {
    uint32_t slot;
    if (!m_freeSlots.empty()) {
        slot = m_freeSlots.back();
        m_freeSlots.pop_back();
    } else {
        slot = uint32_t(m_slotLive.size());
        m_slotLive.push_back(false);
        m_slotGeneration.push_back(0);
    }
    m_slotLive[slot] = true;
    return BlockId{slot, m_slotGeneration[slot]};
}

// Depth-first from `index` without any pruning: every used subtree is walked to its leaves.
template <size_t N>
int32_t NaiveBlockAllocator<N>::addSurfaceInner(int32_t index, const Extent<N>& extent) {
    if (m_nodes[index].childA != kNone) {
        int32_t result = addSurfaceInner(m_nodes[index].childA, extent);
        if (result != kNone) return result;
        return addSurfaceInner(m_nodes[index].childB, extent);
    }
    if (m_nodes[index].used || !fitsIn<N>(extent, m_nodes[index].size)) return kNone;
    size_t axis = block_detail::splitAxis<N>(m_nodes[index].size, extent);
    if (axis == N) {
        m_nodes[index].used = true;
        return index;
    }
    Node a, b;
    a.min = b.min = m_nodes[index].min;
    a.size = b.size = m_nodes[index].size;
    a.size[axis] = extent[axis];
    b.min[axis] += extent[axis];
    b.size[axis] -= extent[axis];
    int32_t first = int32_t(m_nodes.size());
    m_nodes.push_back(a);
    m_nodes.push_back(b);
    m_nodes[index].childA = first;
    m_nodes[index].childB = first + 1;
    return addSurfaceInner(first, extent);
}

template <size_t N>
std::optional<Placement<N>> NaiveBlockAllocator<N>::insert(const Extent<N>& requested) {
    auto extent = block_detail::roundUpExtent<N>(requested, m_nodes[0].size, m_alignment);
    if (!extent) return std::nullopt;
    int32_t index = addSurfaceInner(0, *extent);
    if (index == kNone) return std::nullopt;
    Node& node = m_nodes[index];
    node.id = newId();
    ++m_liveCount;
    m_usedVolume += volume<N>(node.size);
    return Placement<N>{node.min, node.size, node.id};
}

template <size_t N>
std::vector<std::optional<Placement<N>>>
NaiveBlockAllocator<N>::insertBatch(std::span<const Extent<N>> extents) {
    std::vector<std::optional<Placement<N>>> results;
    results.reserve(extents.size());
    for (const auto& extent : extents) results.push_back(insert(extent));
    return results;
}

template <size_t N>
int32_t NaiveBlockAllocator<N>::findParentNode(int32_t index) const {
    for (int32_t i = 0; i < int32_t(m_nodes.size()); ++i)
        if (m_nodes[i].childA == index || m_nodes[i].childB == index) return i;
    return kNone;
}

template <size_t N>
bool NaiveBlockAllocator<N>::isNodeUsed(int32_t index) const {
    bool childrenUsed = false;
    if (m_nodes[index].childA != kNone) childrenUsed |= isNodeUsed(m_nodes[index].childA);
    if (m_nodes[index].childB != kNone) childrenUsed |= isNodeUsed(m_nodes[index].childB);
    return m_nodes[index].used || childrenUsed;
}

// Children are always stored after their parent and the erase preserves order, so `index`
// itself never shifts while its subtree is erased.
template <size_t N>
void NaiveBlockAllocator<N>::removeChildren(int32_t index) {
    if (m_nodes[index].childA != kNone) removeChildren(m_nodes[index].childA);
    if (m_nodes[index].childB != kNone) removeChildren(m_nodes[index].childB);
    for (int32_t Node::*child : {&Node::childA, &Node::childB}) {
        const int32_t old = m_nodes[index].*child;
        if (old == kNone) continue;
        m_nodes.erase(m_nodes.begin() + old);
        for (Node& other : m_nodes) {
            if (other.childA >= old) --other.childA;
            if (other.childB >= old) --other.childB;
        }
        m_nodes[index].*child = kNone;
    }
}

template <size_t N>
void NaiveBlockAllocator<N>::removeNode(int32_t found) {
    Node& node = m_nodes[found];
    node.used = false;
    m_slotLive[node.id.slot] = false;
    ++m_slotGeneration[node.id.slot];
    m_freeSlots.push_back(node.id.slot);
    node.id = BlockId{};
    --m_liveCount;
    m_usedVolume -= volume<N>(node.size);

    int32_t parent = findParentNode(found);
    parent = (parent != kNone && isNodeUsed(parent)) ? kNone : parent;
    int32_t lastParent = parent;
    while (parent != kNone && !isNodeUsed(m_nodes[parent].childA) &&
           !isNodeUsed(m_nodes[parent].childB)) {
        lastParent = parent;
        parent = findParentNode(parent);
    }
    if (lastParent != kNone) removeChildren(lastParent);
}

template <size_t N>
bool NaiveBlockAllocator<N>::remove(const Position<N>& origin) {
    for (int32_t i = 0; i < int32_t(m_nodes.size()); ++i) {
        if (m_nodes[i].used && m_nodes[i].min == origin) {
            removeNode(i);
            return true;
        }
    }
    return false;
}

template <size_t N>
bool NaiveBlockAllocator<N>::remove(BlockId id) {
    if (!id.valid()) return false;
    for (int32_t i = 0; i < int32_t(m_nodes.size()); ++i) {
        if (m_nodes[i].used && m_nodes[i].id == id) {
            removeNode(i);
            return true;
        }
    }
    return false;
}

template <size_t N>
std::vector<BlockTreeNode<N>> NaiveBlockAllocator<N>::preorder() const {
    std::vector<BlockTreeNode<N>> out;
    std::vector<int32_t> stack{0};
    while (!stack.empty()) {
        const Node& node = m_nodes[stack.back()];
        stack.pop_back();
        out.push_back(BlockTreeNode<N>{node.min, node.size, node.childA == kNone, node.used,
                                       node.used ? node.id : BlockId{}});
        if (node.childA != kNone) {
            stack.push_back(node.childB);
            stack.push_back(node.childA);
        }
    }
    return out;
}

template <size_t N>
bool NaiveBlockAllocator<N>::validate() const {
    size_t reached = 0, live = 0;
    uint64_t used = 0;
    std::vector<int32_t> stack{0};
    while (!stack.empty()) {
        int32_t index = stack.back();
        stack.pop_back();
        if (index < 0 || size_t(index) >= m_nodes.size() || ++reached > m_nodes.size())
            return false;
        const Node& node = m_nodes[index];
        if ((node.childA == kNone) != (node.childB == kNone)) return false;
        if (node.childA == kNone) {
            if (node.used) ++live, used += volume<N>(node.size);
            continue;
        }
        if (node.used || node.childA <= index || node.childB <= index) return false;
        const Node& a = m_nodes[node.childA];
        const Node& b = m_nodes[node.childB];
        if (a.min != node.min || volume<N>(a.size) + volume<N>(b.size) != volume<N>(node.size))
            return false;
        stack.push_back(node.childA);
        stack.push_back(node.childB);
    }
    return reached == m_nodes.size() && live == m_liveCount && used == m_usedVolume;
}

template class NaiveBlockAllocator<2>;
template class NaiveBlockAllocator<3>;

} // namespace shadel
