#pragma once
// Guillotine binary-tree block allocator for 2-D and 3-D atlases (the structure of UE4's
// FTextureLayout3d, with parent indices, a tree search, swap-remove with stack fix-up, batched
// insertion and a placement policy that keeps the tree shallow).
//
// Every node is an axis-aligned box; an inner node is cut into two children along one axis.
// Removing an element frees its leaf and collapses the highest ancestor whose subtree is now
// empty back into one free leaf, which restores the largest free box (the same rule as UE4's).
//
// Placement ("halving guillotine"): a free leaf that is at least twice the element on some axis
// is cut in half along the longest such axis (like a 2-D/3-D buddy allocator), and the element
// continues into the first half; once no axis can be halved, the box is cut exactly to the
// element along the axis with the most slack (UE4's rule). So a leaf is at most
// log2(sheet / element) halvings + N exact cuts below the root: 22 levels for a 1024 x 1024 sheet,
// whatever the number of live elements. UE4's rule alone cuts off one element-sized strip per
// element and chains them, which makes trees hundreds of levels deep, and every insertion and
// removal pays for the depth. The free halves are square-ish boxes that later elements reuse,
// and freeing merges them back like buddies.
// Insertion searches depth-first, best fit first (into the child with less free room), so small
// elements fill the holes between placed ones and large free boxes stay whole; that search is
// bounded (a node budget), after which it follows children whose summary guarantees a fitting
// leaf straight down (see FreeSummary).
//
// What makes it fast (the naive baseline in block_allocator_naive.h has none of it):
// - each node stores its parent, so walking up is O(1) per step;
// - "is this subtree empty" is O(1) (an inner node never is, a leaf is when it has no id), so
//   removal climbs only as far as it collapses, not to the root;
// - the node array holds only links and summaries (boxes are in a parallel array), siblings are
//   adjacent and share a cache line (2-D), and an id lookup is one cache line, so each step up
//   a removal costs about one cache line;
// - each node stores a summary of the free leaves below it (per-axis maximum, and the free box
//   with the longest shortest side), so insertion skips subtrees that cannot hold the element
//   instead of walking the whole tree, and removal and insertion refresh these summaries only up
//   to the first ancestor they leave unchanged;
// - removal by position descends the tree (children partition their parent, so one path);
//   removal by id is a table lookup; there is no separate contains-then-remove;
// - nodes are deleted by moving the last node of the array into the hole and fixing its parent,
//   children and id slot, instead of an order-preserving erase and a whole-array index fix-up;
// - insertBatch places many elements in one traversal (largest first), sharing the descent and
//   the summary refresh between them.
// Layouts differ from the naive allocator's (which keeps UE4's placement); both produce valid
// layouts for the same operations, and removal collapses the same way in both, which the
// differential tests check.
#include <array>
#include <cstddef>
#include <cstdint>
#include <new>
#include <optional>
#include <span>
#include <vector>

namespace shadel {

template <size_t N>
using Extent = std::array<uint32_t, N>;
template <size_t N>
using Position = std::array<uint32_t, N>;

namespace block_detail {
// What the free leaves of a subtree offer: `max` is the per-axis maximum over them, `square` the
// size of the free leaf whose shortest side is longest (the first one, child A before child B, on
// ties). Both zero when no leaf is free. An element within `max` *may* fit some free leaf below;
// one that fits `square` *surely* does, and the child `square` came from has the same box, so the
// search can follow such children straight down to a fitting leaf.
template <size_t N>
struct FreeSummary {
    Extent<N> max{};
    Extent<N> square{};
    friend bool operator==(const FreeSummary&, const FreeSummary&) = default;
};
} // namespace block_detail

// Names one placed element. Ids are recycled; the generation makes a stale id harmless.
struct BlockId {
    uint32_t slot = ~0u;
    uint32_t generation = 0;
    bool valid() const { return slot != ~0u; }
    friend bool operator==(const BlockId&, const BlockId&) = default;
};

template <size_t N>
struct Placement {
    Position<N> origin{};
    Extent<N> extent{}; // what was reserved: the request rounded up to the alignment
    BlockId id;
};

// One node of the tree in depth-first order (child A's subtree, then child B's). The same layout
// gives the same list, whatever order the nodes have in memory; used to compare allocators.
template <size_t N>
struct BlockTreeNode {
    Position<N> min{};
    Extent<N> size{};
    bool leaf = true;
    bool used = false;
    BlockId id;
    friend bool operator==(const BlockTreeNode&, const BlockTreeNode&) = default;
};

template <size_t N>
class BlockAllocator {
    static_assert(N == 2 || N == 3, "2-D and 3-D atlases only");

public:
    // Every element's origin and extent become multiples of `alignment` (>= 1); the part of
    // `size` beyond the last multiple of the alignment is not used.
    explicit BlockAllocator(Extent<N> size, uint32_t alignment = 1);

    // nullopt if no free box can hold the element or an axis of `extent` is 0.
    std::optional<Placement<N>> insert(const Extent<N>& extent);
    // Places every element it can in one traversal of the tree: largest first (by volume), each
    // by the same descent rule as insert(); results are in the order of `extents`, and ids are
    // handed out in that order.
    std::vector<std::optional<Placement<N>>> insertBatch(std::span<const Extent<N>> extents);
    // False if no element starts at `origin` (or `id` is stale).
    bool remove(const Position<N>& origin);
    bool remove(BlockId id);
    std::optional<Placement<N>> find(BlockId id) const;
    void clear();

    size_t size() const { return m_liveCount; } // live elements
    uint64_t usedVolume() const { return m_usedVolume; }
    Extent<N> bounds() const { return m_bounds; }
    uint32_t alignment() const { return m_alignment; }
    size_t nodeCount() const { return m_nodes.size() - 1; } // without the padding node

    std::vector<BlockTreeNode<N>> preorder() const;
    // Checks links, the partition of every node by its children, the cached subtree data and the
    // id table (tests and fuzzing).
    bool validate() const;

private:
    static constexpr uint32_t kNone = ~0u;
    static constexpr uint32_t kReservedSlot = ~0u - 1; // used leaf awaiting its id (batches)
    // The tree is split into a hot array (links and summaries, what the searches and the refresh
    // on the way up read) and a cold one (each node's box), so that the part walked on every
    // removal is small and dense. Whether a subtree holds a used leaf is not stored: an inner
    // node always does (empty ones are collapsed), a leaf does when it has an id slot.
    struct alignas(N == 2 ? 32 : 8) Node {
        block_detail::FreeSummary<N> free; // of this subtree's free leaves
        uint32_t parent = kNone;
        uint32_t childA = kNone;
        uint32_t childB = kNone;
        uint32_t slot = kNone; // id slot of the element, for used leaves
        bool leaf() const { return childA == kNone; }
        bool occupied() const { return childA != kNone || slot != kNone; }
    };
    struct Box {
        Position<N> min{};
        Extent<N> size{};
    };
    // The two children of a node are always adjacent, child A at an even index (the root is
    // node 0, node 1 is padding), and the node array starts on a cache line: in 2-D, where a
    // node is 32 bytes, a pair of siblings is one cache line, which is what refreshing a parent
    // reads.
    template <class T>
    struct CacheLineAllocator {
        using value_type = T;
        CacheLineAllocator() = default;
        template <class U>
        CacheLineAllocator(const CacheLineAllocator<U>&) {}
        T* allocate(size_t n) {
            return static_cast<T*>(::operator new (n * sizeof(T), std::align_val_t{64}));
        }
        void deallocate(T* p, size_t) { ::operator delete (p, std::align_val_t{64}); }
        friend bool operator==(const CacheLineAllocator&, const CacheLineAllocator&) {
            return true;
        }
    };
    struct BatchState;
    struct BatchList {
        size_t begin, end;
    };

    std::optional<Extent<N>> roundUp(const Extent<N>& extent) const;
    void splitLeaf(uint32_t index, const Extent<N>& extent);
    uint32_t findLeaf(const Extent<N>& extent, uint32_t start = 0);
    void reserveLeaf(uint32_t index);
    Placement<N> occupyLeaf(uint32_t index);
    bool refresh(uint32_t index);
    void refreshUpwards(uint32_t index, uint32_t through = kNone);
    size_t visitBatch(uint32_t index, BatchState& state, BatchList list);
    void removeLeaf(uint32_t index);
    void collapse(uint32_t& top);

    Extent<N> m_bounds;
    uint32_t m_alignment;
    std::vector<Node, CacheLineAllocator<Node>> m_nodes;
    std::vector<Box> m_boxes; // parallel to m_nodes
    struct Slot {
        uint32_t node = kNone; // node index, kNone when the slot is free
        uint32_t generation = 0;
    };
    std::vector<Slot> m_slots; // by id slot (one cache line per lookup)
    std::vector<uint32_t> m_freeSlots;
    std::vector<uint32_t> m_scratch; // reused traversal stack
    uint32_t m_splitTop = kNone;     // the leaf the last findLeaf() cut, kNone if it cut none
    size_t m_liveCount = 0;
    uint64_t m_usedVolume = 0;
};

using BlockAllocator2D = BlockAllocator<2>;
using BlockAllocator3D = BlockAllocator<3>;

namespace block_detail {
// Shared by the fast and the naive allocator.
template <size_t N>
std::optional<Extent<N>> roundUpExtent(const Extent<N>& extent, const Extent<N>& usable,
                                       uint32_t alignment);
// The axis to cut a free box of `box` size for an element of `element` size: the one with the
// most slack (lowest axis on ties); N when the element fits exactly.
template <size_t N>
size_t splitAxis(const Extent<N>& box, const Extent<N>& element);
template <size_t N>
bool fitsIn(const Extent<N>& element, const Extent<N>& box) {
    for (size_t axis = 0; axis < N; ++axis)
        if (element[axis] > box[axis]) return false;
    return true;
}
template <size_t N>
uint64_t volume(const Extent<N>& extent) {
    uint64_t v = 1;
    for (uint32_t e : extent) v *= e;
    return v;
}
} // namespace block_detail

} // namespace shadel
