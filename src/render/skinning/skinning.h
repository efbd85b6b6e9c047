#pragma once
// GPU skinning: a compute pass at the top of the frame, before every view (shadow
// maps, prepass, marking, shading, reconstruction), writes each skinned vertex as
// sum(weight x joint matrix) applied to its unskinned vertex into a deformed copy of the
// unified vertex buffer; FrameConstants::vertices points every pass at that copy. Joint
// matrices are uploaded per frame (animated playback hands each frame's pose). Meshes the
// importer could not keep whole, or `--skinning cpu`, draw the importer's CPU-skinned vertices.
// The ray-tracing BLASes of skinned meshes are built from the deformed buffer and refit when the
// pose changes (render/raytracing/acceleration_structures.h).
#include <cstdint>
#include <memory>
#include <vector>

#include <vulkan/vulkan.h>

#include "scene/scene.h"

namespace shadel {

struct Renderer;
struct GpuScene;

struct SkinningState;
struct SkinningStateDeleter {
    void operator()(SkinningState* s) const;
};
using SkinningStatePtr = std::unique_ptr<SkinningState, SkinningStateDeleter>;

// Null when the scene has no GPU-skinnable mesh. `scene` is the one `gpuScene` was uploaded from.
SkinningStatePtr createSkinning(Renderer& r, const Scene& scene, const GpuScene& gpuScene);
void destroySkinning(Renderer& r, SkinningState& s);
// This frame's joint matrices (the scene's skin poses, same structure as at creation).
void setSkinPoses(Renderer& r, SkinningState& s, const std::vector<SkinPose>& poses);
// The deformed vertex buffer every pass reads this frame.
uint64_t skinnedVerticesAddress(const Renderer& r, const SkinningState& s);
// The compute pass; its writes are visible to every later vertex, fragment and compute read.
void recordSkinning(Renderer& r, VkCommandBuffer cmd);
uint32_t skinnedVertexCount(const SkinningState& s);
// The meshes whose vertices the pass deforms.
const std::vector<uint32_t>& skinnedMeshes(const SkinningState& s);
// Grows each time setSkinPoses hands over joint matrices that differ from the last ones.
uint64_t skinPoseVersion(const SkinningState& s);

} // namespace shadel
