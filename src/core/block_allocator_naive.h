#pragma once
// The block allocator as UE4's FTextureLayout3d has it, before any optimisation:
// nodes know only their children; removal finds the element by scanning every node, finds each
// parent by scanning every node, asks "is this subtree used" by walking the subtree, and deletes
// nodes with an order-preserving erase followed by a pass over all nodes to fix their indices;
// every insertion walks the tree from the root without pruning, and places elements by UE4's
// rule (first free leaf that fits, cut to the element along the axis with the most slack). Kept
// only as the benchmark baseline and as the oracle for differential tests, through the same
// interface as BlockAllocator (block_allocator.h). BlockAllocator places elements differently
// (it halves large free boxes), so layouts differ; both must be valid for the same operations,
// and removal collapses the same way in both (the tests rebuild this allocator from a fast tree
// with fromPreorder() and compare the trees after each removal).
#include "core/block_allocator.h"

namespace shadel {

template <size_t N>
class NaiveBlockAllocator {
public:
    explicit NaiveBlockAllocator(Extent<N> size, uint32_t alignment = 1);
    // Rebuilds the tree `nodes` describes (as BlockAllocator::preorder() lists it), ids included,
    // so benchmarks can start from a large layout without inserting it at naive speed.
    static NaiveBlockAllocator fromPreorder(Extent<N> size, uint32_t alignment,
                                            std::span<const BlockTreeNode<N>> nodes);

    std::optional<Placement<N>> insert(const Extent<N>& extent);
    // One root walk per element, without batched insertion.
    std::vector<std::optional<Placement<N>>> insertBatch(std::span<const Extent<N>> extents);
    bool remove(const Position<N>& origin);
    bool remove(BlockId id);
    void clear();

    size_t size() const { return m_liveCount; }
    uint64_t usedVolume() const { return m_usedVolume; }
    Extent<N> bounds() const { return m_bounds; }
    uint32_t alignment() const { return m_alignment; }
    size_t nodeCount() const { return m_nodes.size(); }

    std::vector<BlockTreeNode<N>> preorder() const;
    bool validate() const;

private:
    static constexpr int32_t kNone = -1;
    struct Node {
        Position<N> min{};
        Extent<N> size{};
        int32_t childA = kNone;
        int32_t childB = kNone;
        bool used = false;
        BlockId id;
    };

    int32_t addSurfaceInner(int32_t index, const Extent<N>& extent);
    int32_t findParentNode(int32_t index) const;
    bool isNodeUsed(int32_t index) const;
    void removeChildren(int32_t index);
    void removeNode(int32_t found);
    BlockId newId();

    Extent<N> m_bounds;
    uint32_t m_alignment;
    std::vector<Node> m_nodes;
    std::vector<uint32_t> m_slotGeneration;
    std::vector<bool> m_slotLive;
    std::vector<uint32_t> m_freeSlots;
    size_t m_liveCount = 0;
    uint64_t m_usedVolume = 0;
};

using NaiveBlockAllocator2D = NaiveBlockAllocator<2>;
using NaiveBlockAllocator3D = NaiveBlockAllocator<3>;

} // namespace shadel
