#pragma once
// False colour for captured IDs, labels and masks (--capture): every ID gets a stable, well
// separated colour (hashed hue), empty texels stay black; masks become a heat ramp.
#include <cstdint>
#include <vector>

#include "render/debug/capture.h"

namespace shadel {

// A bright colour for an ID (same ID, same colour; neighbouring IDs look different).
void idColour(uint32_t id, uint8_t rgb[3]);
// 0 -> black, then blue, cyan, green, yellow, red, white at `max` and above.
void heatColour(uint32_t value, uint32_t max, uint8_t rgb[3]);
// RGBA8 of a captured image (Display: as is; Ids, Labels: idColour; Mask: heatColour;
// Hdr/Depth: clamped to 0..1 for a quick look).
std::vector<uint8_t> falseColourRgba(const CapturedImage& image);

} // namespace shadel
