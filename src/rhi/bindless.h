#pragma once
// One global descriptor table: every sampled and storage image of the engine sits
// at a persistent slot; shaders index it. Buffers are reached by device address instead.
//
// Static section: slots that live as long as their view. Dynamic section: slots valid for one
// frame. The table is double-buffered: frame N binds set N%2, and writes reach a set only when
// the frame that last used it has completed, so a frame in flight never sees a slot change.
// A freed slot is overwritten with a null (1x1 black) resource before it is reused.
#include <array>
#include <vector>

#include "rhi/handles.h"
#include "rhi/vk.h"

namespace shadel {

struct Gpu;

constexpr uint32_t kBindlessSampledStatic = 16384 - 1024;
constexpr uint32_t kBindlessSampledCapacity = 16384; // last 1024: dynamic section
constexpr uint32_t kBindlessStorageStatic = 4096 - 512;
constexpr uint32_t kBindlessStorageCapacity = 4096;
constexpr uint32_t kBindlessSamplerCount = 4;

// Immutable samplers, indexed in GLSL through shaders/common/bindless.glsl.
enum class SamplerId : uint32_t {
    LinearRepeat = 0,
    LinearClamp = 1,
    NearestClamp = 2,
    ShadowCompare = 3
};

enum class BindlessKind : uint32_t { Sampled = 0, Storage = 1 };

struct BindlessWrite {
    BindlessKind kind;
    uint32_t slot;
    VkImageView view; // VK_NULL_HANDLE = write the null resource
    VkImageLayout layout;
};

struct BindlessTable {
    VkDescriptorSetLayout layout = VK_NULL_HANDLE;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    std::array<VkDescriptorSet, 2> sets{};
    std::array<VkSampler, kBindlessSamplerCount> samplers{};
    VkPipelineLayout pipelineLayout = VK_NULL_HANDLE; // set 0 = this table, 128 B push constants

    // Pending writes per set, applied in prepareBindlessFrame() when that set is not in use.
    std::array<std::vector<BindlessWrite>, 2> pending;
    // Freed slots wait until both sets hold the null resource.
    struct Retired {
        BindlessKind kind;
        uint32_t slot;
        uint32_t setsLeft; // bitmask of sets that still have to apply the null write
    };
    std::vector<Retired> retired;
    std::vector<uint32_t> freeSampled, freeStorage;
    uint32_t nextSampled = 0, nextStorage = 0;
    uint32_t dynamicSampled = 0, dynamicStorage = 0; // per-frame cursors in the dynamic section
    uint32_t current = 0;                            // set used by the frame being recorded
    VkImageView nullSampledView = VK_NULL_HANDLE;
    VkImageView nullStorageView = VK_NULL_HANDLE;
    TextureHandle nullTexture;
    uint32_t staticSampledInUse = 0, staticStorageInUse = 0;
};

void initBindless(Gpu& gpu);
void destroyBindless(Gpu& gpu);

// Static section.
// Sampled views of textures with storage usage are read in GENERAL layout (those textures
// never leave it); all other sampled views in SHADER_READ_ONLY_OPTIMAL.
BindlessSlot allocateBindless(Gpu& gpu, BindlessKind kind, VkImageView view, VkImageLayout layout);
void updateBindless(Gpu& gpu, BindlessKind kind, BindlessSlot slot, VkImageView view,
                    VkImageLayout layout);
void freeBindless(Gpu& gpu, BindlessKind kind, BindlessSlot slot);
// Dynamic section: valid for the frame being recorded only.
BindlessSlot allocateDynamicBindless(Gpu& gpu, BindlessKind kind, VkImageView view,
                                     VkImageLayout layout);

// Called when frame `frameIndex` starts recording, after the frame that last used set
// frameIndex%2 has completed: applies that set's pending writes and resets the dynamic section.
void prepareBindlessFrame(Gpu& gpu, uint64_t frameIndex);
VkDescriptorSet currentBindlessSet(const Gpu& gpu);

} // namespace shadel
