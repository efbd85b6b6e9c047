#include "core/tlsf.h"

#include <bit>

#include "core/assert.h"

namespace shadel {

namespace {

bool isPowerOfTwo(uint64_t value) {
    return value != 0 && (value & (value - 1)) == 0;
}

uint32_t log2Floor(uint64_t value) {
    return 63u - uint32_t(std::countl_zero(value));
}

} // namespace

Tlsf::Tlsf(uint64_t capacity) : m_capacity(capacity) {
    for (auto& lists : m_freeHeads)
        for (uint32_t& head : lists) head = kNone;
    if (capacity == 0) return;
    // Record 0 is the block at offset 0 for the allocator's whole life: merges always keep the
    // lower block's record and splits keep the front record, so validate() can start from it.
    uint32_t first = newBlock();
    m_blocks[first].offset = 0;
    m_blocks[first].size = capacity;
    insertFree(first);
}

// Sizes below 32 map linearly to list (0, size); above, the first level is the power of two and
// the second level is one of 32 equal steps inside it.
Tlsf::ListIndex Tlsf::listFor(uint64_t size) {
    if (size < kSecondLevelCount) return {0, uint32_t(size)};
    uint32_t log2 = log2Floor(size);
    uint32_t second = uint32_t(size >> (log2 - kSecondLevelLog2)) - kSecondLevelCount;
    return {log2 - kSecondLevelLog2 + 1, second};
}

// Finds a list whose every block is at least `size`: round `size` up to the next list boundary,
// then take the first non-empty list at or above it. Two bit scans, no loops.
std::optional<Tlsf::ListIndex> Tlsf::findNonEmptyList(uint64_t size) const {
    if (size >= kSecondLevelCount) {
        uint64_t step = (uint64_t(1) << (log2Floor(size) - kSecondLevelLog2)) - 1;
        if (size > UINT64_MAX - step) return std::nullopt;
        size += step;
    }
    ListIndex list = listFor(size);
    uint32_t secondMask = m_secondLevelBitmap[list.first] & (~0u << list.second);
    if (secondMask == 0) {
        if (list.first + 1 >= kFirstLevelCount) return std::nullopt;
        uint64_t firstMask = m_firstLevelBitmap & (~uint64_t(0) << (list.first + 1));
        if (firstMask == 0) return std::nullopt;
        list.first = uint32_t(std::countr_zero(firstMask));
        secondMask = m_secondLevelBitmap[list.first];
    }
    list.second = uint32_t(std::countr_zero(secondMask));
    return list;
}

uint32_t Tlsf::newBlock() {
    uint32_t index;
    if (m_unusedRecords != kNone) {
        index = m_unusedRecords;
        m_unusedRecords = m_blocks[index].nextFree;
        m_blocks[index] = Block{};
    } else {
        index = uint32_t(m_blocks.size());
        m_blocks.emplace_back();
    }
    m_blocks[index].isLive = true;
    return index;
}

void Tlsf::releaseBlock(uint32_t index) {
    m_blocks[index] = Block{};
    m_blocks[index].nextFree = m_unusedRecords;
    m_unusedRecords = index;
}

void Tlsf::insertFree(uint32_t index) {
    Block& block = m_blocks[index];
    ListIndex list = listFor(block.size);
    uint32_t& head = m_freeHeads[list.first][list.second];
    block.isFree = true;
    block.prevFree = kNone;
    block.nextFree = head;
    if (head != kNone) m_blocks[head].prevFree = index;
    head = index;
    m_firstLevelBitmap |= uint64_t(1) << list.first;
    m_secondLevelBitmap[list.first] |= 1u << list.second;
    ++m_freeBlockCount;
}

void Tlsf::removeFree(uint32_t index) {
    Block& block = m_blocks[index];
    ListIndex list = listFor(block.size);
    if (block.prevFree != kNone)
        m_blocks[block.prevFree].nextFree = block.nextFree;
    else
        m_freeHeads[list.first][list.second] = block.nextFree;
    if (block.nextFree != kNone) m_blocks[block.nextFree].prevFree = block.prevFree;
    if (m_freeHeads[list.first][list.second] == kNone) {
        m_secondLevelBitmap[list.first] &= ~(1u << list.second);
        if (m_secondLevelBitmap[list.first] == 0)
            m_firstLevelBitmap &= ~(uint64_t(1) << list.first);
    }
    block.isFree = false;
    block.prevFree = block.nextFree = kNone;
    --m_freeBlockCount;
}

void Tlsf::splitTail(uint32_t index, uint64_t size) {
    uint32_t tail = newBlock(); // may reallocate m_blocks: index, do not hold references
    Block& block = m_blocks[index];
    Block& rest = m_blocks[tail];
    rest.offset = block.offset + size;
    rest.size = block.size - size;
    rest.prevPhysical = index;
    rest.nextPhysical = block.nextPhysical;
    if (block.nextPhysical != kNone) m_blocks[block.nextPhysical].prevPhysical = tail;
    block.nextPhysical = tail;
    block.size = size;
    insertFree(tail);
}

void Tlsf::mergeWithNext(uint32_t index) {
    uint32_t next = m_blocks[index].nextPhysical;
    Block& block = m_blocks[index];
    Block& absorbed = m_blocks[next];
    block.size += absorbed.size;
    block.nextPhysical = absorbed.nextPhysical;
    if (absorbed.nextPhysical != kNone) m_blocks[absorbed.nextPhysical].prevPhysical = index;
    releaseBlock(next);
}

std::optional<TlsfAllocation> Tlsf::allocate(uint64_t size, uint64_t alignment) {
    if (size == 0 || size > m_capacity || !isPowerOfTwo(alignment)) return std::nullopt;
    auto alignedFits = [&](uint32_t index) {
        const Block& block = m_blocks[index];
        uint64_t aligned = (block.offset + alignment - 1) & ~(alignment - 1);
        return aligned - block.offset <= block.size &&
               block.size - (aligned - block.offset) >= size;
    };
    // The list for `size` usually has a block that is already aligned (offsets of neighbouring
    // allocations are aligned too); only if its head is not, ask for room for the worst padding.
    uint32_t index = kNone;
    if (auto list = findNonEmptyList(size)) {
        uint32_t head = m_freeHeads[list->first][list->second];
        if (alignedFits(head)) index = head;
    }
    if (index == kNone && alignment > 1) {
        if (size > UINT64_MAX - (alignment - 1)) return std::nullopt;
        if (auto list = findNonEmptyList(size + alignment - 1))
            index = m_freeHeads[list->first][list->second];
    }
    if (index == kNone) {
        // Last resort, and the only loop: the rounded searches skip the list `size` itself falls
        // in, whose blocks may be smaller than `size` - or not (a request for a whole fresh pool
        // must succeed). Scan that one list.
        ListIndex list = listFor(size);
        for (uint32_t i = m_freeHeads[list.first][list.second]; i != kNone;
             i = m_blocks[i].nextFree) {
            if (alignedFits(i)) {
                index = i;
                break;
            }
        }
        if (index == kNone) return std::nullopt;
    }
    SHADEL_ASSERT(alignedFits(index));

    removeFree(index);
    uint64_t padding =
        ((m_blocks[index].offset + alignment - 1) & ~(alignment - 1)) - m_blocks[index].offset;
    // Neither neighbour of a free block is free (immediate coalescing), so the pieces we cut off
    // here never need merging.
    if (padding > 0) {
        splitTail(index, padding);
        uint32_t rest = m_blocks[index].nextPhysical;
        removeFree(rest);
        insertFree(index);
        index = rest;
    }
    // Reserve the size rounded up to the alignment when the block has room: the free tail then
    // starts aligned, so the next allocation of that alignment needs no padding block. With
    // mixed sizes this halves the splits and the blocks to walk.
    uint64_t reserved = size;
    uint64_t roundedUp = (size + alignment - 1) & ~(alignment - 1);
    if (roundedUp >= size && roundedUp <= m_blocks[index].size) reserved = roundedUp;
    if (m_blocks[index].size > reserved) splitTail(index, reserved);

    m_used += m_blocks[index].size;
    ++m_allocationCount;
    return TlsfAllocation{m_blocks[index].offset, m_blocks[index].size, index};
}

void Tlsf::free(const TlsfAllocation& allocation) {
    uint32_t index = allocation.blockIndex;
    SHADEL_ASSERT(index < m_blocks.size());
    SHADEL_ASSERT(m_blocks[index].isLive && !m_blocks[index].isFree);
    SHADEL_ASSERT(m_blocks[index].offset == allocation.offset);
    m_used -= m_blocks[index].size;
    --m_allocationCount;

    uint32_t prev = m_blocks[index].prevPhysical;
    if (prev != kNone && m_blocks[prev].isFree) {
        removeFree(prev);
        mergeWithNext(prev);
        index = prev;
    }
    uint32_t next = m_blocks[index].nextPhysical;
    if (next != kNone && m_blocks[next].isFree) {
        removeFree(next);
        mergeWithNext(index);
    }
    insertFree(index);
}

TlsfStats Tlsf::stats() const {
    TlsfStats stats;
    stats.capacity = m_capacity;
    stats.used = m_used;
    stats.free = m_capacity - m_used;
    stats.allocationCount = m_allocationCount;
    stats.freeBlockCount = m_freeBlockCount;
    if (m_firstLevelBitmap != 0) {
        // The largest free block lives in the highest non-empty list; lists are unsorted, so
        // scan that one list.
        uint32_t first = log2Floor(m_firstLevelBitmap);
        uint32_t second = 31u - uint32_t(std::countl_zero(m_secondLevelBitmap[first]));
        for (uint32_t i = m_freeHeads[first][second]; i != kNone; i = m_blocks[i].nextFree)
            if (m_blocks[i].size > stats.largestFree) stats.largestFree = m_blocks[i].size;
    }
    if (stats.free > 0) stats.fragmentation = 1.0 - double(stats.largestFree) / double(stats.free);
    return stats;
}

bool Tlsf::validate() const {
    if (m_capacity == 0) return m_blocks.empty() && m_firstLevelBitmap == 0;
    uint64_t expectedOffset = 0, used = 0;
    uint32_t allocations = 0, freeBlocks = 0, prev = kNone;
    bool prevFree = false;
    for (uint32_t i = 0; i != kNone; i = m_blocks[i].nextPhysical) {
        if (i >= m_blocks.size()) return false;
        const Block& block = m_blocks[i];
        if (!block.isLive || block.size == 0 || block.offset != expectedOffset) return false;
        if (block.prevPhysical != prev) return false;
        if (block.isFree && prevFree) return false; // missed coalescing
        if (block.isFree)
            ++freeBlocks;
        else
            used += block.size, ++allocations;
        expectedOffset += block.size;
        prevFree = block.isFree;
        prev = i;
    }
    if (expectedOffset != m_capacity || used != m_used || allocations != m_allocationCount ||
        freeBlocks != m_freeBlockCount)
        return false;

    uint32_t listed = 0;
    for (uint32_t first = 0; first < kFirstLevelCount; ++first) {
        bool anyInFirst = false;
        for (uint32_t second = 0; second < kSecondLevelCount; ++second) {
            uint32_t head = m_freeHeads[first][second];
            bool bit = (m_secondLevelBitmap[first] >> second) & 1u;
            if (bit != (head != kNone)) return false;
            anyInFirst |= bit;
            uint32_t prevInList = kNone;
            for (uint32_t i = head; i != kNone; i = m_blocks[i].nextFree) {
                const Block& block = m_blocks[i];
                if (!block.isLive || !block.isFree || block.prevFree != prevInList) return false;
                ListIndex list = listFor(block.size);
                if (list.first != first || list.second != second) return false;
                if (++listed > freeBlocks) return false; // also stops a cycle
                prevInList = i;
            }
        }
        if (bool((m_firstLevelBitmap >> first) & 1u) != anyInFirst) return false;
    }
    return listed == freeBlocks;
}

} // namespace shadel
