#pragma once
// Texture streaming: a scene's textures stream from their file (bake/texture_pack.h)
// into a layered cache (texture_cache.h) under a hard memory budget (--texture-budget MiB).
//
// Every scene texture is a logical texture with a persistent bindless slot (materials never
// change); residency changes rebind that slot to another cache image (the table is double-
// buffered, so a frame in flight never sees it change). Per frame:
//   prepare (CPU, before the frame's bindless set is written): last frame's GPU feedback and
//     this frame's CPU estimates merged into priorities; loads that landed are committed
//     (ownership + bindless); new pairwise exchanges are planned and their loads queued.
//   textureStreaming (the frame's first pass): clears the feedback buffer; copies the landed
//     exchanges (the yielding texture's lower levels into the slot it moves down to, then the
//     staging ring's levels into the upgraded slot).
//   shading writes the feedback (shaders/streaming/feedback.glsl).
//   finish (CPU, after the frame): frees the staging the copies used.
// Loads run on a worker thread that reads the file straight into the staging ring; the frame
// only looks at finished loads, it never waits for one.
//
// Without a budget every texture is loaded whole at start from the same file (the "everything
// resident" reference for quality and timing).
//
// The file's textures are BC7 by default (--texture-compression bc: 1 byte a texel, against 4 for
// RGBA8), so every cache image and sparse page holds 4 times the texels; sRGB and linear views
// of the same block data keep colour and data textures sampled as before. Without device support
// for BC sampling (or sparse BC7 images with --streaming sparse) the file is RGBA8, with a warning
// and the reason in the statistics.
//
// --streaming sparse (sparse_textures.h, sparse_residency.h): the same priorities, loads and
// staging ring, but one sparse-resident image per texture whose MIP levels are paged in and out
// of a fixed page pool instead of slots; the slot's view is rebound to start at the resident
// level, and prepare queues the page binds the frame waits on (takeTextureStreamingWait).
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake/texture_pack.h"
#include "common/shared_types.h"
#include "render/camera.h"
#include "render/streaming/texture_cache.h"
#include "rhi/vk.h"
#include "scene/scene.h"

namespace shadel {

struct Gpu;

enum class StreamingMode { Layered, Sparse };

struct TextureStreamingSettings {
    double budgetMiB = 0.0; // 0: no budget, every texture resident at full resolution
    StreamingMode mode = StreamingMode::Layered;
    TextureCompression compression = TextureCompression::Bc; // what the file should hold
    uint32_t stagingMiB = 64; // the staging ring (host memory, not counted in the budget)
    TextureCacheLimits limits;
    float cpuCap = 512.0f;       // CPU estimates count up to this side (see mergedWanted)
    uint32_t feedbackFrames = 8; // a GPU wish holds this many frames after its last sample
};

struct TextureStreaming;
struct TextureStreamingDeleter {
    void operator()(TextureStreaming* s) const;
};
using TextureStreamingPtr = std::unique_ptr<TextureStreaming, TextureStreamingDeleter>;

// Opens (or builds) the scene's streaming file in cacheDir and makes the cache. Throws
// InputError for a budget below what the resident tails need.
TextureStreamingPtr createTextureStreaming(Gpu& gpu, const Scene& scene,
                                           const TextureStreamingSettings& settings,
                                           const std::string& cacheDir);
// One bindless slot per scene texture, for uploadScene's materials.
const std::vector<uint32_t>& streamedTextureSlots(const TextureStreaming& s);

void prepareTextureStreaming(TextureStreaming& s, const CameraView& camera, float viewportHeight,
                             gpu::FrameConstants& constants);
// Per scene material: 1 when a texture it samples changed residency in this frame's prepare
// (shading stored in earlier frames is stale: the decoupled path must not carry it over).
const std::vector<uint8_t>& restreamedMaterials(const TextureStreaming& s);
// --streaming sparse: the semaphore this frame's page binds signal (the frame's first submission
// waits on it), then forgotten; null when nothing was bound.
VkSemaphore takeTextureStreamingWait(TextureStreaming& s);
void recordTextureStreaming(TextureStreaming& s, VkCommandBuffer cmd);
void finishTextureStreamingFrame(TextureStreaming& s);

// "texture_memory_peak_bytes", "texture_total_bytes" (every texture whole with its MIPs as
// stored), "texture_bytes_per_texel" and a "texture_streaming" object (per-frame resident memory,
// exchanges, loads, each texture's format and PSNR against its RGBA8 texels).
void textureStreamingStats(const TextureStreaming& s, nlohmann::json& stats);
uint64_t textureMemoryPeakBytes(const TextureStreaming& s);

} // namespace shadel
