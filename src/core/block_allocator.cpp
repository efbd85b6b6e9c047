#include "core/block_allocator.h"

#include <algorithm>
#include <functional>

#include "core/assert.h"

namespace shadel {

namespace block_detail {

template <size_t N>
std::optional<Extent<N>> roundUpExtent(const Extent<N>& extent, const Extent<N>& usable,
                                       uint32_t alignment) {
    Extent<N> rounded;
    for (size_t axis = 0; axis < N; ++axis) {
        if (extent[axis] == 0 || extent[axis] > usable[axis]) return std::nullopt;
        // usable[axis] is a multiple of the alignment, so this cannot overflow past it.
        rounded[axis] = (extent[axis] + alignment - 1) / alignment * alignment;
    }
    return rounded;
}

template <size_t N>
size_t splitAxis(const Extent<N>& box, const Extent<N>& element) {
    size_t best = N;
    uint32_t bestSlack = 0;
    for (size_t axis = 0; axis < N; ++axis) {
        uint32_t slack = box[axis] - element[axis];
        if (slack > bestSlack) best = axis, bestSlack = slack;
    }
    return best;
}

template std::optional<Extent<2>> roundUpExtent<2>(const Extent<2>&, const Extent<2>&, uint32_t);
template std::optional<Extent<3>> roundUpExtent<3>(const Extent<3>&, const Extent<3>&, uint32_t);
template size_t splitAxis<2>(const Extent<2>&, const Extent<2>&);
template size_t splitAxis<3>(const Extent<3>&, const Extent<3>&);

} // namespace block_detail

using block_detail::fitsIn;
using block_detail::volume;

namespace {

template <size_t N>
Extent<N> componentMax(const Extent<N>& a, const Extent<N>& b) {
    Extent<N> out;
    for (size_t axis = 0; axis < N; ++axis) out[axis] = std::max(a[axis], b[axis]);
    return out;
}

template <size_t N>
bool contains(const Position<N>& min, const Extent<N>& size, const Position<N>& point) {
    for (size_t axis = 0; axis < N; ++axis)
        if (point[axis] < min[axis] || point[axis] - min[axis] >= size[axis]) return false;
    return true;
}

} // namespace

template <size_t N>
BlockAllocator<N>::BlockAllocator(Extent<N> size, uint32_t alignment)
    : m_bounds(size), m_alignment(std::max(alignment, 1u)) {
    clear();
}

template <size_t N>
void BlockAllocator<N>::clear() {
    m_nodes.clear();
    Node root;
    for (size_t axis = 0; axis < N; ++axis)
        root.size[axis] = m_bounds[axis] / m_alignment * m_alignment;
    root.maxFree = root.size;
    m_nodes.push_back(root);
    // Bump live slots' generations so that ids handed out before clear() stay invalid.
    m_freeSlots.clear();
    for (uint32_t slot = 0; slot < m_slotNode.size(); ++slot) {
        if (m_slotNode[slot] != kNone) ++m_slotGeneration[slot];
        m_slotNode[slot] = kNone;
    }
    for (uint32_t slot = uint32_t(m_slotNode.size()); slot-- > 0;) m_freeSlots.push_back(slot);
    m_liveCount = 0;
    m_usedVolume = 0;
}

template <size_t N>
std::optional<Extent<N>> BlockAllocator<N>::roundUp(const Extent<N>& extent) const {
    return block_detail::roundUpExtent<N>(extent, m_nodes[0].size, m_alignment);
}

// Recomputes the cached subtree data of an inner node from its children; false if unchanged.
template <size_t N>
bool BlockAllocator<N>::refresh(uint32_t index) {
    Node& node = m_nodes[index];
    const Node& a = m_nodes[node.childA];
    const Node& b = m_nodes[node.childB];
    bool occupied = a.occupied || b.occupied;
    Extent<N> maxFree = componentMax<N>(a.maxFree, b.maxFree);
    if (occupied == node.occupied && maxFree == node.maxFree) return false;
    node.occupied = occupied;
    node.maxFree = maxFree;
    return true;
}

// Once a node's cached data comes out unchanged, nothing above it changes either: trees that
// grew long chains only pay for the part of the path that actually changed.
template <size_t N>
void BlockAllocator<N>::refreshUpwards(uint32_t index) {
    for (; index != kNone && refresh(index); index = m_nodes[index].parent) {
    }
}

// Cuts free leaf `index` once, along the axis with the most slack; child A is the part whose
// extent on that axis matches the element.
template <size_t N>
void BlockAllocator<N>::splitLeaf(uint32_t index, const Extent<N>& extent) {
    size_t axis = block_detail::splitAxis<N>(m_nodes[index].size, extent);
    SHADEL_ASSERT(axis < N);
    Node a, b;
    a.min = b.min = m_nodes[index].min;
    a.size = b.size = m_nodes[index].size;
    a.size[axis] = extent[axis];
    b.min[axis] += extent[axis];
    b.size[axis] -= extent[axis];
    a.maxFree = a.size;
    b.maxFree = b.size;
    a.parent = b.parent = index;
    uint32_t first = uint32_t(m_nodes.size());
    m_nodes.push_back(a);
    m_nodes.push_back(b);
    m_nodes[index].childA = first;
    m_nodes[index].childB = first + 1;
    m_nodes[index].maxFree = componentMax<N>(a.maxFree, b.maxFree);
}

// Marks an exactly fitting free (or batch-reserved) leaf used and gives it an id. Ancestors are
// refreshed by the caller.
template <size_t N>
Placement<N> BlockAllocator<N>::occupyLeaf(uint32_t index) {
    uint32_t slot;
    if (!m_freeSlots.empty()) {
        slot = m_freeSlots.back();
        m_freeSlots.pop_back();
    } else {
        slot = uint32_t(m_slotNode.size());
        m_slotNode.push_back(kNone);
        m_slotGeneration.push_back(0);
    }
    m_slotNode[slot] = index;
    Node& node = m_nodes[index];
    node.slot = slot;
    node.occupied = true;
    node.maxFree = Extent<N>{};
    ++m_liveCount;
    m_usedVolume += volume<N>(node.size);
    return Placement<N>{node.min, node.size, BlockId{slot, m_slotGeneration[slot]}};
}

template <size_t N>
std::optional<Placement<N>> BlockAllocator<N>::insert(const Extent<N>& requested) {
    auto extent = roundUp(requested);
    if (!extent || !fitsIn<N>(*extent, m_nodes[0].maxFree)) return std::nullopt;
    // Depth-first, A before B, entering only subtrees whose per-axis free maximum admits the
    // element. The maximum is per axis, so a subtree can pass and still hold no fitting leaf;
    // the stack keeps the B siblings to come back to.
    m_scratch.clear();
    uint32_t index = 0;
    while (!m_nodes[index].leaf()) {
        const Node& node = m_nodes[index];
        bool intoA = fitsIn<N>(*extent, m_nodes[node.childA].maxFree);
        bool intoB = fitsIn<N>(*extent, m_nodes[node.childB].maxFree);
        if (intoA) {
            if (intoB) m_scratch.push_back(node.childB);
            index = node.childA;
        } else if (intoB) {
            index = node.childB;
        } else {
            if (m_scratch.empty()) return std::nullopt;
            index = m_scratch.back();
            m_scratch.pop_back();
        }
    }
    // A leaf is only entered when its maxFree admits the element: it is free and large enough.
    while (block_detail::splitAxis<N>(m_nodes[index].size, *extent) < N) {
        splitLeaf(index, *extent);
        index = m_nodes[index].childA;
    }
    Placement<N> placement = occupyLeaf(index);
    refreshUpwards(m_nodes[index].parent);
    return placement;
}

template <size_t N>
struct BlockAllocator<N>::BatchState {
    std::span<const Extent<N>> extents; // rounded
    std::vector<uint32_t> pending;      // element numbers still unplaced, ascending
    Extent<N> smallest;                 // per-axis minimum over the initial pending set
    std::vector<uint32_t> leaves;       // element number -> leaf it got, or kNone
};

// One depth-first traversal for the whole batch. At a free leaf the lowest-numbered pending
// element that fits is placed, and the traversal continues into the pieces cut off, so the
// result equals inserting the elements one by one (first fit in the same order), without
// walking down from the root for each of them.
template <size_t N>
void BlockAllocator<N>::visitBatch(uint32_t index, BatchState& state) {
    if (state.pending.empty() || !fitsIn<N>(state.smallest, m_nodes[index].maxFree)) return;
    if (m_nodes[index].leaf()) {
        if (m_nodes[index].slot != kNone) return;
        auto fitting = std::find_if(state.pending.begin(), state.pending.end(), [&](uint32_t e) {
            return fitsIn<N>(state.extents[e], m_nodes[index].size);
        });
        if (fitting == state.pending.end()) return;
        const Extent<N>& extent = state.extents[*fitting];
        if (block_detail::splitAxis<N>(m_nodes[index].size, extent) == N) {
            // Ids are handed out after the traversal, in element order, as insert() would.
            Node& node = m_nodes[index];
            node.slot = kReservedSlot;
            node.occupied = true;
            node.maxFree = Extent<N>{};
            state.leaves[*fitting] = index;
            state.pending.erase(fitting);
            return; // the caller refreshes this node's ancestors
        }
        // Lower-numbered pending elements did not fit this leaf, so they will not fit child A
        // either: the element will be found again there.
        splitLeaf(index, extent);
    } else {
        bool any = false;
        for (uint32_t e : state.pending) {
            if (fitsIn<N>(state.extents[e], m_nodes[index].maxFree)) {
                any = true;
                break;
            }
        }
        if (!any) return;
    }
    visitBatch(m_nodes[index].childA, state);
    visitBatch(m_nodes[index].childB, state);
    refresh(index);
}

template <size_t N>
std::vector<std::optional<Placement<N>>>
BlockAllocator<N>::insertBatch(std::span<const Extent<N>> extents) {
    std::vector<std::optional<Placement<N>>> results(extents.size());
    std::vector<Extent<N>> rounded(extents.size());
    BatchState state;
    state.leaves.assign(extents.size(), kNone);
    state.smallest.fill(~0u);
    for (uint32_t e = 0; e < extents.size(); ++e) {
        auto extent = roundUp(extents[e]);
        if (!extent) continue;
        rounded[e] = *extent;
        state.pending.push_back(e);
        for (size_t axis = 0; axis < N; ++axis)
            state.smallest[axis] = std::min(state.smallest[axis], rounded[e][axis]);
    }
    state.extents = rounded;
    visitBatch(0, state);
    for (uint32_t e = 0; e < extents.size(); ++e)
        if (state.leaves[e] != kNone) results[e] = occupyLeaf(state.leaves[e]);
    return results;
}

template <size_t N>
bool BlockAllocator<N>::remove(const Position<N>& origin) {
    if (!contains<N>(m_nodes[0].min, m_nodes[0].size, origin)) return false;
    // Children partition their parent, so exactly one child contains the point.
    uint32_t index = 0;
    while (!m_nodes[index].leaf()) {
        const Node& a = m_nodes[m_nodes[index].childA];
        index = contains<N>(a.min, a.size, origin) ? m_nodes[index].childA : m_nodes[index].childB;
    }
    if (m_nodes[index].slot == kNone || m_nodes[index].min != origin) return false;
    removeLeaf(index);
    return true;
}

template <size_t N>
bool BlockAllocator<N>::remove(BlockId id) {
    if (id.slot >= m_slotNode.size() || m_slotNode[id.slot] == kNone ||
        m_slotGeneration[id.slot] != id.generation)
        return false;
    removeLeaf(m_slotNode[id.slot]);
    return true;
}

template <size_t N>
std::optional<Placement<N>> BlockAllocator<N>::find(BlockId id) const {
    if (id.slot >= m_slotNode.size() || m_slotNode[id.slot] == kNone ||
        m_slotGeneration[id.slot] != id.generation)
        return std::nullopt;
    const Node& node = m_nodes[m_slotNode[id.slot]];
    return Placement<N>{node.min, node.size, id};
}

template <size_t N>
void BlockAllocator<N>::removeLeaf(uint32_t index) {
    Node& node = m_nodes[index];
    uint32_t slot = node.slot;
    m_slotNode[slot] = kNone;
    ++m_slotGeneration[slot];
    m_freeSlots.push_back(slot);
    node.slot = kNone;
    node.occupied = false;
    node.maxFree = node.size;
    --m_liveCount;
    m_usedVolume -= volume<N>(node.size);

    // Climb while the sibling subtree is empty too: those ancestors just became empty, and the
    // highest of them is collapsed back into one free leaf, restoring the box as it was before
    // it was cut. The first ancestor with an occupied sibling stays occupied: stop there.
    uint32_t top = kNone;
    for (uint32_t child = index, p = node.parent; p != kNone; child = p, p = m_nodes[p].parent) {
        const Node& parent = m_nodes[p];
        uint32_t sibling = parent.childA == child ? parent.childB : parent.childA;
        if (m_nodes[sibling].occupied) break;
        m_nodes[p].occupied = false;
        top = p;
    }
    uint32_t changed = index;
    if (top != kNone) {
        collapse(top);
        changed = top;
    }
    refreshUpwards(m_nodes[changed].parent);
}

// Deletes every node below `top` and makes `top` a free leaf. Each deleted slot is filled with
// the array's last node (swap-remove), whose parent, children and id slot are then re-pointed.
// Deleting in descending index order means the last node is never one still to be deleted, so
// no traversal state needs fixing except `top` itself, which may be the node that moves.
template <size_t N>
void BlockAllocator<N>::collapse(uint32_t& top) {
    m_scratch.clear();
    m_scratch.push_back(m_nodes[top].childA);
    m_scratch.push_back(m_nodes[top].childB);
    for (size_t i = 0; i < m_scratch.size(); ++i) {
        const Node& node = m_nodes[m_scratch[i]];
        if (!node.leaf()) {
            m_scratch.push_back(node.childA);
            m_scratch.push_back(node.childB);
        }
    }
    Node& collapsed = m_nodes[top];
    collapsed.childA = collapsed.childB = kNone;
    collapsed.maxFree = collapsed.size;
    std::sort(m_scratch.begin(), m_scratch.end(), std::greater<>());
    for (uint32_t hole : m_scratch) {
        uint32_t last = uint32_t(m_nodes.size() - 1);
        if (hole != last) {
            Node& moved = m_nodes[hole];
            moved = m_nodes[last];
            Node& parent = m_nodes[moved.parent];
            (parent.childA == last ? parent.childA : parent.childB) = hole;
            if (!moved.leaf()) {
                m_nodes[moved.childA].parent = hole;
                m_nodes[moved.childB].parent = hole;
            }
            if (moved.slot != kNone) m_slotNode[moved.slot] = hole;
            if (top == last) top = hole;
        }
        m_nodes.pop_back();
    }
}

template <size_t N>
std::vector<BlockTreeNode<N>> BlockAllocator<N>::preorder() const {
    std::vector<BlockTreeNode<N>> out;
    out.reserve(m_nodes.size());
    std::vector<uint32_t> stack{0};
    while (!stack.empty()) {
        const Node& node = m_nodes[stack.back()];
        stack.pop_back();
        BlockTreeNode<N> entry{node.min, node.size, node.leaf(), node.slot != kNone, BlockId{}};
        if (entry.used) entry.id = BlockId{node.slot, m_slotGeneration[node.slot]};
        out.push_back(entry);
        if (!node.leaf()) {
            stack.push_back(node.childB);
            stack.push_back(node.childA);
        }
    }
    return out;
}

template <size_t N>
bool BlockAllocator<N>::validate() const {
    if (m_nodes.empty() || m_nodes[0].parent != kNone || m_nodes[0].min != Position<N>{})
        return false;
    for (size_t axis = 0; axis < N; ++axis)
        if (m_nodes[0].size[axis] != m_bounds[axis] / m_alignment * m_alignment) return false;
    size_t reached = 0, live = 0;
    uint64_t usedVolume = 0;
    std::vector<uint32_t> stack{0};
    while (!stack.empty()) {
        uint32_t index = stack.back();
        stack.pop_back();
        if (index >= m_nodes.size() || ++reached > m_nodes.size()) return false;
        const Node& node = m_nodes[index];
        for (size_t axis = 0; axis < N; ++axis)
            if (node.min[axis] % m_alignment || node.size[axis] % m_alignment) return false;
        if (node.leaf()) {
            if (node.childB != kNone) return false;
            bool used = node.slot != kNone;
            if (node.occupied != used) return false;
            if (node.maxFree != (used ? Extent<N>{} : node.size)) return false;
            if (used) {
                if (node.slot >= m_slotNode.size() || m_slotNode[node.slot] != index) return false;
                ++live;
                usedVolume += volume<N>(node.size);
            }
            continue;
        }
        if (node.slot != kNone || node.childB == kNone) return false;
        if (node.childA >= m_nodes.size() || node.childB >= m_nodes.size()) return false;
        const Node& a = m_nodes[node.childA];
        const Node& b = m_nodes[node.childB];
        if (a.parent != index || b.parent != index) return false;
        // The children must tile the parent: equal on all axes but one, adjacent along it.
        size_t cutAxes = 0;
        for (size_t axis = 0; axis < N; ++axis) {
            if (a.min[axis] != node.min[axis]) return false;
            if (a.size[axis] == node.size[axis] && b.size[axis] == node.size[axis] &&
                b.min[axis] == node.min[axis])
                continue;
            ++cutAxes;
            if (a.size[axis] == 0 || b.size[axis] == 0) return false;
            if (a.size[axis] + b.size[axis] != node.size[axis]) return false;
            if (b.min[axis] != node.min[axis] + a.size[axis]) return false;
        }
        if (cutAxes != 1) return false;
        if (node.occupied != (a.occupied || b.occupied)) return false;
        if (!node.occupied) return false; // an empty inner node should have collapsed
        if (node.maxFree != componentMax<N>(a.maxFree, b.maxFree)) return false;
        stack.push_back(node.childA);
        stack.push_back(node.childB);
    }
    if (reached != m_nodes.size() || live != m_liveCount || usedVolume != m_usedVolume)
        return false;
    size_t liveSlots = 0;
    for (uint32_t node : m_slotNode) liveSlots += node != kNone;
    return liveSlots == m_liveCount && liveSlots + m_freeSlots.size() == m_slotNode.size();
}

template class BlockAllocator<2>;
template class BlockAllocator<3>;

} // namespace shadel
