#pragma once
// Frame extraction (capture any resource and show it): each technique registers the
// images and buffers of its frame under a name (`--capture NAME`); after the frame's GPU work
// has finished, a registered source reads its resource back into a CapturedImage, and the app
// writes it (src/app/capture_output.h): EXR for HDR colour and depth, PNG for display formats,
// false colour for IDs and masks.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "rhi/handles.h"
#include "rhi/vk.h"

namespace shadel {

struct Gpu;

// How a captured resource is meant to be looked at (and so which file it becomes).
enum class CaptureKind {
    Hdr,     // linear float RGBA -> EXR
    Depth,   // one float channel -> EXR
    Display, // RGBA8 -> PNG
    Ids,     // two uints per texel (e.g. instance, triangle) -> false-colour PNG
    Mask,    // a count per texel (e.g. occupancy bits set, 0..64) -> heat-map PNG
    Labels,  // one uint label per texel, 0 = empty -> false-colour PNG
};

struct CapturedImage {
    CaptureKind kind = CaptureKind::Hdr;
    uint32_t width = 0, height = 0;
    uint32_t channels = 0;       // of `floats` (Hdr: 4, Depth: 1) or `uints` (Ids: 2, others: 1)
    std::vector<float> floats;   // Hdr, Depth
    std::vector<uint32_t> uints; // Ids, Mask, Labels
    std::vector<uint8_t> rgba8;  // Display
    uint32_t maskMax = 64;       // Mask: the value shown hottest
};

struct CaptureSource {
    std::string name;
    std::string what; // one line for `--capture list`
    CaptureKind kind;
    std::function<CapturedImage()> read; // only after the frame's GPU work has finished
};

struct CaptureRegistry {
    std::vector<CaptureSource> sources;
};

void registerCapture(CaptureRegistry& registry, std::string name, std::string what,
                     CaptureKind kind, std::function<CapturedImage()> read);
const CaptureSource* findCapture(const CaptureRegistry& registry, const std::string& name);
std::string captureNames(const CaptureRegistry& registry); // "a, b, c"

// Reads mip 0 of a texture that the frame left in `layout` (it is left in that layout again).
// Converts RGBA16F / RGBA32F / D32 to floats, RGBA8 to bytes, R32G32_UINT / R32_UINT to uints.
CapturedImage readTexture(Gpu& gpu, TextureHandle texture, VkImageLayout layout, CaptureKind kind);
// A texture the frame leaves in `layout`, captured as `kind` (one line per registration).
void registerTextureCapture(CaptureRegistry& registry, Gpu& gpu, std::string name, std::string what,
                            CaptureKind kind, std::function<TextureHandle()> texture,
                            VkImageLayout layout);
// A buffer of side x side 64-bit masks, shown as bits set per mask (Mask, 0..64).
CapturedImage readMaskGrid(Gpu& gpu, BufferHandle masks, uint32_t side);
// A buffer of side x side uint labels, 0 = empty (Labels).
CapturedImage readLabelGrid(Gpu& gpu, BufferHandle labels, uint32_t side);

} // namespace shadel
