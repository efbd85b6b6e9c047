#pragma once
// Two-level segregated fit allocator (Masmano et al. 2004) over an abstract range of offsets
// [0, capacity). It never touches the memory it manages, so it can sub-allocate device memory or
// one big buffer. Allocate and free are O(1): a first-level bitmap picks the power-of-two size
// class, a second-level bitmap picks one of 32 linear subdivisions inside it, and freed blocks
// are merged with their physical neighbours immediately.
#include <cstdint>
#include <optional>
#include <vector>

namespace shadel {

struct TlsfAllocation {
    uint64_t offset = 0;
    uint64_t size = 0;         // reserved: the size asked for, rounded up to the alignment
                               // when that fits (so the next free block starts aligned)
    uint32_t blockIndex = ~0u; // internal handle: which block record owns this range
};

struct TlsfStats {
    uint64_t capacity = 0;
    uint64_t used = 0;        // sum of allocated block sizes (alignment padding counts as free)
    uint64_t free = 0;        // capacity - used
    uint64_t largestFree = 0; // biggest single free block
    uint32_t allocationCount = 0;
    uint32_t freeBlockCount = 0;
    double fragmentation = 0; // 1 - largestFree / free; 0 when nothing or everything is free
};

class Tlsf {
public:
    explicit Tlsf(uint64_t capacity);

    // Returns std::nullopt when no free block can hold `size` bytes at `alignment` (any power of
    // two); also for size 0 or a non-power-of-two alignment. Never aborts. O(1) when a block of
    // a larger size class is free; otherwise it scans the one list of `size`'s own class.
    std::optional<TlsfAllocation> allocate(uint64_t size, uint64_t alignment = 1);
    // `allocation` must come from this allocator and not have been freed already (asserted).
    void free(const TlsfAllocation& allocation);

    TlsfStats stats() const;
    uint64_t capacity() const { return m_capacity; }
    uint32_t allocationCount() const { return m_allocationCount; }
    uint64_t used() const { return m_used; }
    bool empty() const { return m_allocationCount == 0; }

    // Walks every block and list and checks the allocator's invariants (tests and fuzzing).
    bool validate() const;

private:
    static constexpr uint32_t kSecondLevelLog2 = 5;
    static constexpr uint32_t kSecondLevelCount = 1u << kSecondLevelLog2;
    static constexpr uint32_t kFirstLevelCount = 64 - kSecondLevelLog2 + 1;
    static constexpr uint32_t kNone = ~0u;

    struct Block {
        uint64_t offset = 0;
        uint64_t size = 0;
        uint32_t prevPhysical = kNone;
        uint32_t nextPhysical = kNone;
        uint32_t prevFree = kNone; // free-list links while free; nextFree links the record pool
        uint32_t nextFree = kNone; // while the record is unused
        bool isFree = false;
        bool isLive = false; // the record describes a block (as opposed to a recycled record)
    };

    struct ListIndex {
        uint32_t first;
        uint32_t second;
    };
    static ListIndex listFor(uint64_t size);
    std::optional<ListIndex> findNonEmptyList(uint64_t size) const;

    uint32_t newBlock();
    void releaseBlock(uint32_t index);
    void insertFree(uint32_t index);
    void removeFree(uint32_t index);
    // Cuts `index` so that it keeps its first `size` units; the tail becomes a new free block.
    void splitTail(uint32_t index, uint64_t size);
    void mergeWithNext(uint32_t index);

    uint64_t m_capacity;
    uint64_t m_used = 0;
    uint32_t m_allocationCount = 0;
    uint32_t m_freeBlockCount = 0;
    uint64_t m_firstLevelBitmap = 0;
    uint32_t m_secondLevelBitmap[kFirstLevelCount] = {};
    uint32_t m_freeHeads[kFirstLevelCount][kSecondLevelCount];
    std::vector<Block> m_blocks;
    uint32_t m_unusedRecords = kNone; // recycled Block records, linked through nextFree
};

} // namespace shadel
