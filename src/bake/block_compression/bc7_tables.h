#pragma once
// The BC7 format's fixed tables: interpolation weights, the 64 two-subset and 64 three-subset
// partitions (subset of texel i: bit i of a two-subset mask, bits 2i..2i+1 of a three-subset
// one) and the anchor texels whose index drops its top bit. Used by the encoder and decoder.
#include <cstdint>

namespace shadel::bc7 {

extern const uint8_t kWeights2[4], kWeights3[8], kWeights4[16];
extern const uint16_t kPartitions2[64];
extern const uint32_t kPartitions3[64];
extern const uint8_t kAnchor2[64];       // second subset's anchor, two subsets
extern const uint8_t kAnchor3Second[64]; // second subset's anchor, three subsets
extern const uint8_t kAnchor3Third[64];  // third subset's anchor, three subsets

inline const uint8_t* weights(uint32_t indexBits) {
    return indexBits == 2 ? kWeights2 : indexBits == 3 ? kWeights3 : kWeights4;
}
inline uint32_t subsetOf(uint32_t subsets, uint32_t partition, uint32_t texel) {
    if (subsets == 1) return 0;
    if (subsets == 2) return (kPartitions2[partition] >> texel) & 1u;
    return (kPartitions3[partition] >> (2 * texel)) & 3u;
}
inline uint32_t anchorOf(uint32_t subsets, uint32_t partition, uint32_t subset) {
    if (subset == 0) return 0;
    if (subsets == 2) return kAnchor2[partition];
    return subset == 1 ? kAnchor3Second[partition] : kAnchor3Third[partition];
}

// One mode's layout: subsets, partition bits, rotation bits, index-selection bit, colour and
// alpha endpoint bits, p-bits (0 none, 1 one per subset, 2 one per endpoint), index bits
// (primary, secondary).
struct Mode {
    uint8_t subsets, partitionBits, rotationBits, indexSelectionBits, colorBits, alphaBits, pbits,
        indexBits, indexBits2;
};
extern const Mode kModes[8];

} // namespace shadel::bc7
