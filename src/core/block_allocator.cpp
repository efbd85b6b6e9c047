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

using block_detail::FreeSummary;

template <size_t N>
uint32_t shortestSide(const Extent<N>& e) {
    uint32_t m = e[0];
    for (size_t d = 1; d < N; ++d) m = std::min(m, e[d]);
    return m;
}

template <size_t N>
FreeSummary<N> summaryOfLeaf(const Extent<N>& size) {
    return FreeSummary<N>{size, size};
}

template <size_t N>
FreeSummary<N> combine(const FreeSummary<N>& a, const FreeSummary<N>& b) {
    FreeSummary<N> out;
    for (size_t d = 0; d < N; ++d) out.max[d] = std::max(a.max[d], b.max[d]);
    out.square = shortestSide<N>(a.square) >= shortestSide<N>(b.square) ? a.square : b.square;
    return out;
}

// How well a subtree's free leaves can take an element: 0 not at all, 1 maybe (the per-axis
// maximum admits it), 2 surely (the summary's square leaf holds it).
enum Fit { kNoFit = 0, kMayFit = 1, kSureFit = 2 };

template <size_t N>
Fit fitOf(const Extent<N>& element, const FreeSummary<N>& summary) {
    if (!fitsIn<N>(element, summary.max)) return kNoFit;
    return fitsIn<N>(element, summary.square) ? kSureFit : kMayFit;
}

// Which child an element tries first when both may hold it: the one with less free room (best
// fit: small elements fill small holes, large free boxes stay whole for large elements), child A
// on ties.
template <size_t N>
bool aFirst(const FreeSummary<N>& a, const FreeSummary<N>& b) {
    return volume<N>(a.max) <= volume<N>(b.max);
}

// Nodes a search may visit following "maybe" before it settles for a box it is sure of. Filling
// the holes between placed elements first keeps the layout compact (and the tree small); the
// budget keeps a search among holes that turn out too small for the element from walking a large
// part of the tree.
constexpr uint32_t kSearchBudget = 32;

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
    m_boxes.clear();
    Box root;
    for (size_t axis = 0; axis < N; ++axis)
        root.size[axis] = m_bounds[axis] / m_alignment * m_alignment;
    m_nodes.push_back(Node{summaryOfLeaf<N>(root.size)});
    m_boxes.push_back(root);
    m_nodes.push_back(Node{}); // padding: sibling pairs start at even indices
    m_boxes.push_back(Box{});
    // Bump live slots' generations so that ids handed out before clear() stay invalid.
    m_freeSlots.clear();
    for (uint32_t slot = 0; slot < m_slots.size(); ++slot) {
        if (m_slots[slot].node != kNone) ++m_slots[slot].generation;
        m_slots[slot].node = kNone;
    }
    for (uint32_t slot = uint32_t(m_slots.size()); slot-- > 0;) m_freeSlots.push_back(slot);
    m_liveCount = 0;
    m_usedVolume = 0;
}

template <size_t N>
std::optional<Extent<N>> BlockAllocator<N>::roundUp(const Extent<N>& extent) const {
    return block_detail::roundUpExtent<N>(extent, m_boxes[0].size, m_alignment);
}

// Recomputes the cached subtree data of an inner node from its children; false if unchanged.
template <size_t N>
bool BlockAllocator<N>::refresh(uint32_t index) {
    Node& node = m_nodes[index];
    const Node& a = m_nodes[node.childA];
    const Node& b = m_nodes[node.childB];
    FreeSummary<N> free = combine<N>(a.free, b.free);
    if (free == node.free) return false;
    node.free = free;
    return true;
}

// Once a node's summary comes out unchanged, nothing above it changes either: trees that grew
// long chains only pay for the part of the path that actually changed. That holds only where
// the summaries were consistent before the change; the nodes just cut by splitLeaf() (up to and
// including `through`, an ancestor of `index`) are not, and are refreshed regardless.
template <size_t N>
void BlockAllocator<N>::refreshUpwards(uint32_t index, uint32_t through) {
    if (through != kNone) {
        for (bool last = false; !last; index = m_nodes[index].parent) {
            last = index == through;
            refresh(index);
        }
    }
    for (; index != kNone && refresh(index); index = m_nodes[index].parent) {
    }
}

// Cuts free leaf `index` once on the way to an element of `extent` (which fits it and is not
// equal to it); child A is the part the element continues into. A box at least twice the element
// on some axis is halved along the longest such axis (child A, the lower half, is never the
// larger one); otherwise it is cut to the element's extent along the axis with the most slack.
template <size_t N>
void BlockAllocator<N>::splitLeaf(uint32_t index, const Extent<N>& extent) {
    const Extent<N> box = m_boxes[index].size;
    size_t axis = N;
    uint32_t cut = 0;
    for (size_t d = 0; d < N; ++d) {
        uint32_t half = box[d] / m_alignment / 2 * m_alignment;
        if (half >= extent[d] && (axis == N || box[d] > box[axis])) axis = d, cut = half;
    }
    if (axis == N) {
        axis = block_detail::splitAxis<N>(box, extent);
        SHADEL_ASSERT(axis < N);
        cut = extent[axis];
    }
    Box boxA, boxB;
    boxA.min = boxB.min = m_boxes[index].min;
    boxA.size = boxB.size = box;
    boxA.size[axis] = cut;
    boxB.min[axis] += cut;
    boxB.size[axis] -= cut;
    Node a, b;
    a.free = summaryOfLeaf<N>(boxA.size);
    b.free = summaryOfLeaf<N>(boxB.size);
    a.parent = b.parent = index;
    uint32_t first = uint32_t(m_nodes.size());
    m_nodes.push_back(a);
    m_nodes.push_back(b);
    m_boxes.push_back(boxA);
    m_boxes.push_back(boxB);
    m_nodes[index].childA = first;
    m_nodes[index].childB = first + 1;
    m_nodes[index].free = combine<N>(a.free, b.free);
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
        slot = uint32_t(m_slots.size());
        m_slots.push_back(Slot{});
    }
    m_slots[slot].node = index;
    Node& node = m_nodes[index];
    node.slot = slot;
    node.free = FreeSummary<N>{};
    const Box& box = m_boxes[index];
    ++m_liveCount;
    m_usedVolume += volume<N>(box.size);
    return Placement<N>{box.min, box.size, BlockId{slot, m_slots[slot].generation}};
}

// Finds a free leaf below `start` for an element of (rounded) `extent` and cuts it down to the
// element's size; kNone if there is none. The leaf is left free: the caller occupies or reserves
// it and refreshes the summaries above it.
template <size_t N>
uint32_t BlockAllocator<N>::findLeaf(const Extent<N>& extent, uint32_t start) {
    const Fit rootFit = fitOf<N>(extent, m_nodes[start].free);
    if (rootFit == kNoFit) return kNone;
    // Depth-first, best fit first, entering every subtree whose per-axis maximum admits the
    // element; the stack keeps the siblings not taken, to come back to when a subtree holds no
    // fitting leaf after all. Once that search has used its budget, and the root surely holds the
    // element, it follows children that surely hold it straight down instead.
    m_scratch.clear();
    m_splitTop = kNone;
    uint32_t index = start;
    uint32_t budget = kSearchBudget;
    while (!m_nodes[index].leaf()) {
        if (budget == 0 && rootFit == kSureFit) {
            index = start;
            while (!m_nodes[index].leaf()) {
                const Node& node = m_nodes[index];
                const FreeSummary<N>& freeA = m_nodes[node.childA].free;
                const FreeSummary<N>& freeB = m_nodes[node.childB].free;
                bool sureA = fitOf<N>(extent, freeA) == kSureFit;
                bool sureB = fitOf<N>(extent, freeB) == kSureFit;
                SHADEL_ASSERT(sureA || sureB);
                index = sureA && (!sureB || aFirst<N>(freeA, freeB)) ? node.childA : node.childB;
            }
            break;
        }
        budget -= budget > 0;
        const Node& node = m_nodes[index];
        const FreeSummary<N>& freeA = m_nodes[node.childA].free;
        const FreeSummary<N>& freeB = m_nodes[node.childB].free;
        bool intoA = fitOf<N>(extent, freeA) != kNoFit;
        bool intoB = fitOf<N>(extent, freeB) != kNoFit;
        if (intoA && intoB) {
            bool a = aFirst<N>(freeA, freeB);
            m_scratch.push_back(a ? node.childB : node.childA);
            index = a ? node.childA : node.childB;
        } else if (intoA || intoB) {
            index = intoA ? node.childA : node.childB;
        } else {
            if (m_scratch.empty()) return kNone;
            index = m_scratch.back();
            m_scratch.pop_back();
        }
    }
    // A leaf is only entered when its summary admits the element: it is free and large enough.
    if (m_boxes[index].size != extent) m_splitTop = index;
    while (m_boxes[index].size != extent) {
        splitLeaf(index, extent);
        index = m_nodes[index].childA;
    }
    return index;
}

template <size_t N>
std::optional<Placement<N>> BlockAllocator<N>::insert(const Extent<N>& requested) {
    auto extent = roundUp(requested);
    if (!extent) return std::nullopt;
    uint32_t index = findLeaf(*extent);
    if (index == kNone) return std::nullopt;
    Placement<N> placement = occupyLeaf(index);
    refreshUpwards(m_nodes[index].parent, m_splitTop);
    return placement;
}

template <size_t N>
struct BlockAllocator<N>::BatchState {
    std::vector<Extent<N>> extents; // by rank: rank 0 is the largest element
    std::vector<uint32_t> leaves;   // by rank: the leaf reserved for it, or kNone
    std::vector<uint32_t> arena;    // lists of ranks, ascending, stacked by the recursion
    std::vector<uint32_t> scratch;  // never held across a recursive call
    size_t budget = 0;              // node visits left for following "maybe"
};

// Places what it can of the elements listed in state.arena[list] (ranks, ascending) in the
// subtree of `index`; the ones left over are moved to the front of the list, still ascending,
// and the end of that part is returned. Arena entries above list.end are scratch for the
// children's lists and are given back before returning.
//
// At a free leaf the largest element that fits is placed, cutting the leaf as insert() would and
// continuing into the pieces. At an inner node each element goes to the child insert() would try
// first (per the summaries as they are when the node routes it); what child A could not take
// tries B, and what B could not take tries A if it started in B. As in insert(), subtrees that
// only "may" hold an element are entered while the batch's search budget (insert()'s budget per
// element) lasts, and after that only subtrees that surely hold it; insertBatch() gives the few
// elements left over to insert()'s search. The elements share the descent, and each node's
// summary is refreshed once per batch, on the way back up.
// Marks a leaf used by a batch element; ids are handed out after the whole batch is placed, in
// element order.
template <size_t N>
void BlockAllocator<N>::reserveLeaf(uint32_t index) {
    Node& node = m_nodes[index];
    node.slot = kReservedSlot;
    node.free = FreeSummary<N>{};
}

template <size_t N>
size_t BlockAllocator<N>::visitBatch(uint32_t index, BatchState& state, BatchList list) {
    std::vector<uint32_t>& arena = state.arena;
    if (m_nodes[index].leaf()) {
        if (m_nodes[index].slot != kNone) return list.end;
        size_t pick = list.begin;
        while (pick < list.end && !fitsIn<N>(state.extents[arena[pick]], m_boxes[index].size))
            ++pick;
        if (pick == list.end) return list.end;
        const uint32_t rank = arena[pick];
        if (m_boxes[index].size == state.extents[rank]) {
            reserveLeaf(index);
            state.leaves[rank] = index;
            std::copy(arena.begin() + ptrdiff_t(pick) + 1, arena.begin() + ptrdiff_t(list.end),
                      arena.begin() + ptrdiff_t(pick));
            return list.end - 1; // the caller refreshes this node's ancestors
        }
        // Cut the leaf down to this element and place it; the elements before `pick` did not fit
        // the whole leaf, and the others continue into the pieces cut off.
        uint32_t leaf = index;
        while (m_boxes[leaf].size != state.extents[rank]) {
            splitLeaf(leaf, state.extents[rank]);
            leaf = m_nodes[leaf].childA;
        }
        reserveLeaf(leaf);
        state.leaves[rank] = leaf;
        for (uint32_t p = m_nodes[leaf].parent; p != index; p = m_nodes[p].parent) refresh(p);
        std::copy(arena.begin() + ptrdiff_t(pick) + 1, arena.begin() + ptrdiff_t(list.end),
                  arena.begin() + ptrdiff_t(pick));
        if (--list.end == list.begin) {
            refresh(index);
            return list.end;
        }
    } else if (list.end - list.begin == 1) {
        // A single element left on this path: insert()'s search from here does the same, cheaper.
        const uint32_t rank = arena[list.begin];
        uint32_t leaf = findLeaf(state.extents[rank], index);
        if (leaf == kNone) return list.end;
        reserveLeaf(leaf);
        state.leaves[rank] = leaf;
        uint32_t p = m_nodes[leaf].parent;
        for (bool last = m_splitTop == kNone; !last; p = m_nodes[p].parent) {
            last = p == m_splitTop;
            refresh(p);
        }
        for (; p != m_nodes[index].parent && refresh(p); p = m_nodes[p].parent) {
        }
        return list.begin;
    }
    const uint32_t childA = m_nodes[index].childA, childB = m_nodes[index].childB;
    state.budget -= state.budget > 0;
    const Fit enough = state.budget > 0 ? kMayFit : kSureFit;
    auto admits = [&](uint32_t child, uint32_t rank) {
        return fitOf<N>(state.extents[rank], m_nodes[child].free) >= enough;
    };
    // Route: elements no child surely holds stay at the front [list.begin, kept); the others are
    // appended as A's list [base, splitAt) and B's list [splitAt, endB).
    const size_t base = arena.size();
    std::vector<uint32_t>& bFirst = state.scratch;
    bFirst.clear();
    size_t kept = list.begin;
    for (size_t i = list.begin; i < list.end; ++i) {
        const uint32_t rank = arena[i];
        const Extent<N>& e = state.extents[rank];
        const FreeSummary<N>& freeA = m_nodes[childA].free;
        const FreeSummary<N>& freeB = m_nodes[childB].free;
        bool intoA = fitOf<N>(e, freeA) >= enough, intoB = fitOf<N>(e, freeB) >= enough;
        if (!intoA && !intoB)
            arena[kept++] = rank;
        else if (intoA && (!intoB || aFirst<N>(freeA, freeB)))
            arena.push_back(rank);
        else
            bFirst.push_back(rank);
    }
    const size_t splitAt = arena.size();
    arena.insert(arena.end(), bFirst.begin(), bFirst.end());
    const size_t endB = arena.size();

    // A's list; its leftovers that B surely holds are merged (by rank) into B's list, the others
    // are final and compacted to [base, leftA).
    size_t leftA = splitAt == base ? base : visitBatch(childA, state, {base, splitAt});
    const size_t toB = arena.size();
    {
        size_t i = base, j = splitAt, keepA = base;
        while (i < leftA || j < endB) {
            bool fromA = j == endB || (i < leftA && arena[i] < arena[j]);
            const uint32_t rank = arena[fromA ? i++ : j++];
            if (fromA && !admits(childB, rank))
                arena[keepA++] = rank;
            else
                arena.push_back(rank);
        }
        leftA = keepA;
    }
    // B's list; its leftovers that started in B and that A surely holds retry A, the others are
    // final and compacted to [toB, leftB).
    size_t leftB = toB == arena.size() ? toB : visitBatch(childB, state, {toB, arena.size()});
    const size_t retry = arena.size();
    {
        size_t j = splitAt, keepB = toB;
        for (size_t i = toB; i < leftB; ++i) {
            const uint32_t rank = arena[i];
            while (j < endB && arena[j] < rank) ++j;
            bool startedInB = j < endB && arena[j] == rank;
            if (startedInB && admits(childA, rank))
                arena.push_back(rank);
            else
                arena[keepB++] = rank;
        }
        leftB = keepB;
    }
    size_t leftRetry =
        retry == arena.size() ? retry : visitBatch(childA, state, {retry, arena.size()});

    // Every leftover, ascending, back to the front of the list.
    std::vector<uint32_t>& left = state.scratch;
    left.clear();
    left.insert(left.end(), arena.begin() + ptrdiff_t(list.begin), arena.begin() + ptrdiff_t(kept));
    left.insert(left.end(), arena.begin() + ptrdiff_t(base), arena.begin() + ptrdiff_t(leftA));
    left.insert(left.end(), arena.begin() + ptrdiff_t(toB), arena.begin() + ptrdiff_t(leftB));
    left.insert(left.end(), arena.begin() + ptrdiff_t(retry), arena.begin() + ptrdiff_t(leftRetry));
    std::sort(left.begin(), left.end());
    std::copy(left.begin(), left.end(), arena.begin() + ptrdiff_t(list.begin));
    arena.resize(base);
    refresh(index);
    return list.begin + left.size();
}

template <size_t N>
std::vector<std::optional<Placement<N>>>
BlockAllocator<N>::insertBatch(std::span<const Extent<N>> extents) {
    std::vector<std::optional<Placement<N>>> results(extents.size());
    // Rank the elements that can fit at all, largest volume first (longest side, then element
    // order on ties): placing large elements first packs better, and a leaf then takes the
    // first element of its list that fits.
    std::vector<uint32_t> byRank;
    std::vector<Extent<N>> rounded(extents.size());
    for (uint32_t e = 0; e < extents.size(); ++e) {
        auto extent = roundUp(extents[e]);
        if (!extent) continue;
        rounded[e] = *extent;
        byRank.push_back(e);
    }
    auto longest = [](const Extent<N>& x) { return *std::max_element(x.begin(), x.end()); };
    std::stable_sort(byRank.begin(), byRank.end(), [&](uint32_t x, uint32_t y) {
        uint64_t vx = volume<N>(rounded[x]), vy = volume<N>(rounded[y]);
        if (vx != vy) return vx > vy;
        return longest(rounded[x]) > longest(rounded[y]);
    });
    BatchState state;
    state.leaves.assign(byRank.size(), kNone);
    for (uint32_t e : byRank) state.extents.push_back(rounded[e]);
    for (uint32_t rank = 0; rank < byRank.size(); ++rank)
        if (fitOf<N>(state.extents[rank], m_nodes[0].free) != kNoFit) state.arena.push_back(rank);
    state.budget = kSearchBudget;
    if (!state.arena.empty()) visitBatch(0, state, {0, state.arena.size()});
    // What the traversal left (room taken by larger elements of the batch, or only "maybe" room)
    // gets insert()'s full search, largest first.
    for (uint32_t rank = 0; rank < byRank.size(); ++rank) {
        if (state.leaves[rank] != kNone) continue;
        uint32_t leaf = findLeaf(state.extents[rank]);
        if (leaf == kNone) continue;
        reserveLeaf(leaf);
        refreshUpwards(m_nodes[leaf].parent, m_splitTop);
        state.leaves[rank] = leaf;
    }
    std::vector<uint32_t> leafOf(extents.size(), kNone);
    for (uint32_t rank = 0; rank < byRank.size(); ++rank) leafOf[byRank[rank]] = state.leaves[rank];
    for (uint32_t e = 0; e < extents.size(); ++e)
        if (leafOf[e] != kNone) results[e] = occupyLeaf(leafOf[e]);
    return results;
}

template <size_t N>
bool BlockAllocator<N>::remove(const Position<N>& origin) {
    if (!contains<N>(m_boxes[0].min, m_boxes[0].size, origin)) return false;
    // Children partition their parent, so exactly one child contains the point.
    uint32_t index = 0;
    while (!m_nodes[index].leaf()) {
        const Node& node = m_nodes[index];
        const Box& a = m_boxes[node.childA];
        index = contains<N>(a.min, a.size, origin) ? node.childA : node.childB;
    }
    if (m_nodes[index].slot == kNone || m_boxes[index].min != origin) return false;
    removeLeaf(index);
    return true;
}

template <size_t N>
bool BlockAllocator<N>::remove(BlockId id) {
    if (id.slot >= m_slots.size() || m_slots[id.slot].node == kNone ||
        m_slots[id.slot].generation != id.generation)
        return false;
    removeLeaf(m_slots[id.slot].node);
    return true;
}

template <size_t N>
std::optional<Placement<N>> BlockAllocator<N>::find(BlockId id) const {
    if (id.slot >= m_slots.size() || m_slots[id.slot].node == kNone ||
        m_slots[id.slot].generation != id.generation)
        return std::nullopt;
    const Box& box = m_boxes[m_slots[id.slot].node];
    return Placement<N>{box.min, box.size, id};
}

template <size_t N>
void BlockAllocator<N>::removeLeaf(uint32_t index) {
    Node& node = m_nodes[index];
    uint32_t slot = node.slot;
    m_slots[slot].node = kNone;
    ++m_slots[slot].generation;
    m_freeSlots.push_back(slot);
    node.slot = kNone;
    const Extent<N> size = m_boxes[index].size;
    node.free = summaryOfLeaf<N>(size);
    --m_liveCount;
    m_usedVolume -= volume<N>(size);

    // Climb while the sibling subtree is empty too: those ancestors just became empty, and the
    // highest of them is collapsed back into one free leaf, restoring the box as it was before
    // it was cut. The first ancestor with an occupied sibling stays occupied: stop there.
    uint32_t top = kNone;
    for (uint32_t child = index, p = node.parent; p != kNone; child = p, p = m_nodes[p].parent) {
        const Node& parent = m_nodes[p];
        uint32_t sibling = parent.childA == child ? parent.childB : parent.childA;
        if (m_nodes[sibling].occupied()) break;
        top = p;
    }
    uint32_t changed = index;
    if (top != kNone) {
        collapse(top);
        changed = top;
    }
    refreshUpwards(m_nodes[changed].parent);
}

// Deletes every node below `top` and makes `top` a free leaf. Siblings are deleted as a pair:
// each deleted pair is filled with the array's last pair (swap-remove), whose parent, children
// and id slots are then re-pointed. Deleting in descending index order means the last pair is
// never one still to be deleted, so no traversal state needs fixing except `top` itself, which
// may be a node that moves.
template <size_t N>
void BlockAllocator<N>::collapse(uint32_t& top) {
    // The child A of every deleted pair.
    m_scratch.clear();
    m_scratch.push_back(m_nodes[top].childA);
    for (size_t i = 0; i < m_scratch.size(); ++i) {
        for (uint32_t child = m_scratch[i]; child < m_scratch[i] + 2; ++child)
            if (!m_nodes[child].leaf()) m_scratch.push_back(m_nodes[child].childA);
    }
    Node& collapsed = m_nodes[top];
    collapsed.childA = collapsed.childB = kNone;
    collapsed.free = summaryOfLeaf<N>(m_boxes[top].size);
    std::sort(m_scratch.begin(), m_scratch.end(), std::greater<>());
    for (uint32_t hole : m_scratch) {
        uint32_t last = uint32_t(m_nodes.size() - 2);
        if (hole != last) {
            for (uint32_t k = 0; k < 2; ++k) {
                Node& moved = m_nodes[hole + k];
                moved = m_nodes[last + k];
                m_boxes[hole + k] = m_boxes[last + k];
                if (!moved.leaf()) {
                    m_nodes[moved.childA].parent = hole + k;
                    m_nodes[moved.childB].parent = hole + k;
                }
                if (moved.slot != kNone && moved.slot != kReservedSlot)
                    m_slots[moved.slot].node = hole + k;
                if (top == last + k) top = hole + k;
            }
            Node& parent = m_nodes[m_nodes[hole].parent];
            parent.childA = hole;
            parent.childB = hole + 1;
        }
        m_nodes.resize(m_nodes.size() - 2);
        m_boxes.resize(m_boxes.size() - 2);
    }
}

template <size_t N>
std::vector<BlockTreeNode<N>> BlockAllocator<N>::preorder() const {
    std::vector<BlockTreeNode<N>> out;
    out.reserve(m_nodes.size());
    std::vector<uint32_t> stack{0};
    while (!stack.empty()) {
        const Node& node = m_nodes[stack.back()];
        const Box& box = m_boxes[stack.back()];
        stack.pop_back();
        BlockTreeNode<N> entry{box.min, box.size, node.leaf(), node.slot != kNone, BlockId{}};
        if (entry.used) entry.id = BlockId{node.slot, m_slots[node.slot].generation};
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
    if (m_nodes.empty() || m_boxes.size() != m_nodes.size() || m_nodes[0].parent != kNone ||
        m_boxes[0].min != Position<N>{})
        return false;
    for (size_t axis = 0; axis < N; ++axis)
        if (m_boxes[0].size[axis] != m_bounds[axis] / m_alignment * m_alignment) return false;
    size_t reached = 0, live = 0;
    uint64_t usedVolume = 0;
    std::vector<uint32_t> stack{0};
    while (!stack.empty()) {
        uint32_t index = stack.back();
        stack.pop_back();
        if (index >= m_nodes.size() || ++reached >= m_nodes.size()) return false;
        const Node& node = m_nodes[index];
        const Box& box = m_boxes[index];
        for (size_t axis = 0; axis < N; ++axis)
            if (box.min[axis] % m_alignment || box.size[axis] % m_alignment) return false;
        if (node.leaf()) {
            if (node.childB != kNone) return false;
            bool used = node.slot != kNone;
            if (node.free != (used ? FreeSummary<N>{} : summaryOfLeaf<N>(box.size))) return false;
            if (used) {
                if (node.slot >= m_slots.size() || m_slots[node.slot].node != index) return false;
                ++live;
                usedVolume += volume<N>(box.size);
            }
            continue;
        }
        if (node.slot != kNone || node.childB == kNone) return false;
        if (node.childA >= m_nodes.size() || node.childB != node.childA + 1 || node.childA % 2)
            return false;
        if (m_nodes[node.childA].parent != index || m_nodes[node.childB].parent != index)
            return false;
        const Box& a = m_boxes[node.childA];
        const Box& b = m_boxes[node.childB];
        // The children must tile the parent: equal on all axes but one, adjacent along it.
        size_t cutAxes = 0;
        for (size_t axis = 0; axis < N; ++axis) {
            if (a.min[axis] != box.min[axis]) return false;
            if (a.size[axis] == box.size[axis] && b.size[axis] == box.size[axis] &&
                b.min[axis] == box.min[axis])
                continue;
            ++cutAxes;
            if (a.size[axis] == 0 || b.size[axis] == 0) return false;
            if (a.size[axis] + b.size[axis] != box.size[axis]) return false;
            if (b.min[axis] != box.min[axis] + a.size[axis]) return false;
        }
        if (cutAxes != 1) return false;
        // An empty inner node should have collapsed: some child must hold a used leaf (inner
        // children are checked the same way further down).
        const Node& nodeA = m_nodes[node.childA];
        const Node& nodeB = m_nodes[node.childB];
        if (!nodeA.occupied() && !nodeB.occupied()) return false;
        if (node.free != combine<N>(nodeA.free, nodeB.free)) return false;
        stack.push_back(node.childA);
        stack.push_back(node.childB);
    }
    if (reached + 1 != m_nodes.size() || live != m_liveCount || usedVolume != m_usedVolume)
        return false;
    size_t liveSlots = 0;
    for (const Slot& entry : m_slots) liveSlots += entry.node != kNone;
    return liveSlots == m_liveCount && liveSlots + m_freeSlots.size() == m_slots.size();
}

template class BlockAllocator<2>;
template class BlockAllocator<3>;

} // namespace shadel
