#pragma once
// Light propagation volume GI (after Kaplanyan and Dachsbacher 2010): reflective
// shadow maps from the sun and shadow-casting spots, injected as 2-band SH into three
// camera-centred cascades of 32^3 cells (snapped to their cell size so they do not swim),
// propagated N steps with geometry occlusion, plus up to two fixed local volumes an artist
// places (GiLocalVolume, computed once), and read by the shared lighting code
// (shaders/gi/lpv_sample.glsl via shaders/common/lighting.glsl).
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <nlohmann/json_fwd.hpp>

#include "common/shared_types.h"
#include "rhi/vk.h"

namespace shadel {

struct Renderer;
struct GpuScene;
struct CameraView;
struct GiState;

// A light blocker as GI uses it: a rectangle (say a wall's mid-plane) that light does
// not propagate through, stored per cascade as axial occlusion (how much of each cell face it
// covers along x, y, z), with portals (holes light passes through). The scene's light blockers
// (Scene::LightBlocker, direct lighting's) become these (giBlockersOf), so GI and direct light
// stop at the same walls and pass the same doorways.
struct GiBlocker {
    glm::vec3 center{0.0f};
    glm::vec3 axisU{1, 0, 0};       // unit, in the plane
    glm::vec3 axisV{0, 1, 0};       // unit, in the plane, orthogonal to axisU
    glm::vec2 halfSize{1.0f};       // along axisU, axisV
    std::vector<glm::vec4> portals; // min u, min v, max u, max v: metres along axisU, axisV
};

// A local volume (Scene::GiVolume, placed by an artist): the same
// grid as a cascade, cubic, centred on the box and just covering its longest side; it never
// moves, so it is injected and propagated only when the lights change, and the apply reads it
// before the camera cascades wherever it holds the point.
struct GiLocalVolume {
    std::string name;
    glm::vec3 min{0.0f}, max{0.0f};
};

struct Scene;
// The scene's light blockers as GI blockers (the same rectangles and portals).
std::vector<GiBlocker> giBlockersOf(const Scene& scene);
// The scene's local GI volumes, at most GI_MAX_LOCAL_VOLUMES (the rest are counted in dropped).
std::vector<GiLocalVolume> giLocalVolumesOf(const Scene& scene, size_t& dropped);

struct GiStateDeleter {
    void operator()(GiState* state) const;
};
using GiStatePtr = std::unique_ptr<GiState, GiStateDeleter>;

GiStatePtr createGi(Renderer& r, const GpuScene& scene);
void destroyGi(Renderer& r, GiStatePtr& state);

// CPU side of the frame: places the cascades around the camera and points constants.gi at them.
// Call after the frame constants are filled (it reads the sun's view).
void prepareGiFrame(Renderer& r, const GpuScene& scene, const CameraView& camera,
                    gpu::FrameConstants& constants);
// The passes, in frame order (after instance culling, before shading).
void recordGiReflectiveShadowMaps(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
void recordGiInjection(Renderer& r, VkCommandBuffer cmd);
void recordGiPropagation(Renderer& r, VkCommandBuffer cmd);

// Stats "gi": cascades (origin, cell size, extent), cells, RSMs, iterations.
void giStats(const Renderer& r, nlohmann::json& stats);

} // namespace shadel
