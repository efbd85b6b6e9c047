#pragma once
// Mesh distance fields on the GPU (--distance-fields on): the fields of the scene's
// opaque meshes (bake/mesh_distance_field.h, built on the CPU and cached) placed in one 3-D
// atlas by the 3-D block allocator (df_atlas.h), a list of the instances that cast, and a compute
// pass over the surface tiles that sphere-traces soft sun shadows and ambient occlusion
// (shaders/distance_fields). The atlas is a storage buffer addressed as a volume (trilinear by
// hand), not a 3-D image: the rhi has 2-D textures only.
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "rhi/vk.h"

namespace shadel {

struct Renderer;
struct Scene;
struct GpuScene;
struct DistanceFieldState;

struct DistanceFieldStateDeleter {
    void operator()(DistanceFieldState* s) const;
};
using DistanceFieldStatePtr = std::unique_ptr<DistanceFieldState, DistanceFieldStateDeleter>;

// Builds (or reads from `cacheDir`) every field, fills the atlas and uploads it.
DistanceFieldStatePtr createDistanceFields(Renderer& r, const Scene& scene,
                                           const GpuScene& gpuScene, const std::string& cacheDir);
void destroyDistanceFields(Renderer& r, DistanceFieldState& s);
// Before each frame: with --df-residency, the fields of meshes with an instance within that
// distance of the camera come into the atlas, and those not wanted for a few frames leave it
// (their room is reused). Without it every field was placed at load and this does nothing.
void updateDistanceFieldResidency(Renderer& r, DistanceFieldState& s, glm::vec3 camera);
// The scene instances whose field came into the atlas or left it this frame: their DF shadows
// and occlusion appeared or vanished (the decoupled reuse reshades where they fall).
const std::vector<uint32_t>& distanceFieldRelitInstances(const DistanceFieldState& s);

// For the screen-space passes (render/screenspace): the DistanceFieldFrame address and the
// output image's storage slot; the pass itself; its output read back after the frame.
uint64_t distanceFieldFrameAddress(const Renderer& r, const DistanceFieldState& s);
uint32_t distanceFieldOutputSlot(const Renderer& r, const DistanceFieldState& s);
void beginDistanceFieldOutput(Renderer& r, DistanceFieldState& s, VkCommandBuffer cmd);
void recordDistanceFieldReadback(Renderer& r, DistanceFieldState& s, VkCommandBuffer cmd);
// After the frame: compares the DF sun visibility with the shadow map's where both are defined.
void finishDistanceFieldFrame(Renderer& r, DistanceFieldState& s);
void distanceFieldStats(const DistanceFieldState& s, nlohmann::json& stats);

} // namespace shadel
