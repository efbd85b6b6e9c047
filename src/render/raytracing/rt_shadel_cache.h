#pragma once
// The shadel path's ray-traced terms, traced once per shadel and reused: every
// instance shaded in shadel space this frame gets a rect in a persistent atlas at one MIP of its
// shadel space, --rt-shadel-mip-offset levels coarser than the finest its view can need, kept
// while it stays in view. Each frame `rtShadelTrace` traces --rays-per-shadel rays per texel and
// averages them into the texel's history (reset when the rect is new or the instance moved), so
// the result converges over frames in object space and does not swim with the camera. Texels
// much finer on screen than the MIP was chosen for (the far part of a large object) share one
// traced history per 2x2 block; while texels hold few rays, reads pool their neighbours'. Shading
// (shaders/shadel/shade.comp) reads it bilinearly through raytracing/rt_apply.glsl.
#include <memory>
#include <optional>
#include <vector>

#include "common/shared_types.h"
#include "core/block_allocator.h"
#include "raytracing/rt_types.h"
#include "rhi/gpu.h"
#include "rhi/pipeline.h"

namespace shadel {

struct Renderer;
struct GpuScene;
struct CameraView;

struct RtShadelCache {
    uint32_t atlasSize = 0;
    TextureHandle terms, indirect; // rgba16f, GENERAL
    TextureHandle spots;           // rgba32ui, GENERAL: spot visibilities, 8 bits each
    TextureWriteView termsWrite, indirectWrite, spotsWrite;
    TextureReadView termsRead, indirectRead, spotsRead;
    std::unique_ptr<BlockAllocator<2>> atlas;
    struct Entry {
        std::optional<Placement<2>> placement;
        uint32_t level = 0;
        glm::mat4 model{0.0f};
        uint64_t lastSeen = 0;
    };
    std::vector<Entry> entries; // per instance
    std::vector<gpu::RtShadelObject> objects;
    std::vector<gpu::RtShadelTile> tiles;
    BufferHandle objectBuffer, tileBuffer; // host-visible
    Pipeline trace;
    uint32_t tileCount = 0;
    uint32_t texelsTraced = 0; // this frame
    uint32_t instancesCached = 0;
    uint32_t instancesWithoutRoom = 0; // visible decoupled instances the atlas had no room for
    uint64_t historyResets = 0;        // over the run: instance rects whose history restarted
};

// spotShadows: with the rgba32ui layer of the shadow-casting spots' visibilities.
void createRtShadelCache(Renderer& r, const GpuScene& scene, bool spotShadows,
                         RtShadelCache& cache);
void destroyRtShadelCache(Renderer& r, RtShadelCache& cache);
// CPU: rects for this frame's decoupled instances, the tiles to trace; fills rt's cache fields.
void prepareRtShadelCache(Renderer& r, const GpuScene& scene, const CameraView& camera,
                          RtShadelCache& cache, gpu::RtFrame& rt);
void recordRtShadelTrace(Renderer& r, VkCommandBuffer cmd, uint64_t frame, RtShadelCache& cache);

} // namespace shadel
