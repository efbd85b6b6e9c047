#include "render/shadel/coarse_visit.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/cpu_scope.h"
#include "render/culling/instance_grid.h"
#include "render/gpu_scene.h"

namespace shadel {

namespace {

// No footprint bound: the finest MIP is needed whatever the bias.
constexpr float kNeedsMip0 = -std::numeric_limits<float>::infinity();

// The footprint half of an instance's finest MIP (finestMipFromLod adds the bias): a lower bound of
// the instance's screen footprint in MIP-0 shadels. The nearest view depth of the (margin-
// padded) bounds bounds every point's depth; a pixel there spans at least depth * cos(the
// screen's half-diagonal angle) / focal world units in any screen direction; one world unit
// holds at most shadelsPerUnit / (largest scale of the instance) MIP-0 shadels on average, and
// charts vary around that average (stretch, density CV <= 0.2), hence one MIP of slack.
float footprintLod(const CameraView& camera, float viewportHeight, const gpu::GpuInstance& inst,
                   const ShadelMeshInfo& mesh, glm::vec3 boundsMin, glm::vec3 boundsMax) {
    if (mesh.shadelsPerUnit <= 0.0f || mesh.mipCount <= 1) return kNeedsMip0;
    float nearestDepth = 1e30f;
    for (int c = 0; c < 8; ++c) {
        glm::vec3 corner{c & 1 ? boundsMax.x : boundsMin.x, c & 2 ? boundsMax.y : boundsMin.y,
                         c & 4 ? boundsMax.z : boundsMin.z};
        nearestDepth = std::min(nearestDepth, -(camera.view * glm::vec4(corner, 1.0f)).z);
    }
    if (nearestDepth <= camera.znear) return kNeedsMip0;
    float tanX = 1.0f / std::abs(camera.proj[0][0]), tanY = 1.0f / std::abs(camera.proj[1][1]);
    float cosEdge = 1.0f / std::sqrt(1.0f + tanX * tanX + tanY * tanY);
    float focal = 0.5f * viewportHeight * std::abs(camera.proj[1][1]);
    float pixelWorld = nearestDepth * cosEdge / focal;
    glm::mat3 m(inst.model);
    float scale = std::max({glm::length(m[0]), glm::length(m[1]), glm::length(m[2]), 1e-12f});
    constexpr float kDensitySlack = 0.5f;
    float footprint = pixelWorld * mesh.shadelsPerUnit / scale * kDensitySlack;
    return std::log2(std::max(footprint, 1e-12f));
}

bool boxVisible(const std::array<glm::vec4, 6>& planes, glm::vec3 bmin, glm::vec3 bmax) {
    for (const glm::vec4& p : planes) {
        glm::vec3 v{p.x >= 0 ? bmax.x : bmin.x, p.y >= 0 ? bmax.y : bmin.y,
                    p.z >= 0 ? bmax.z : bmin.z};
        if (glm::dot(glm::vec3(p), v) + p.w < 0) return false;
    }
    return true;
}

// Projected diameter in pixels of a world-space sphere (for the hybrid forward policy).
float projectedDiameter(const CameraView& camera, float viewportHeight, glm::vec3 center,
                        float radius) {
    float distance = glm::length(center - camera.position);
    if (distance <= radius) return 1e9f; // the camera is inside: treat as huge
    float focal = 0.5f * viewportHeight * std::abs(camera.proj[1][1]);
    return 2.0f * radius * focal / std::sqrt(distance * distance - radius * radius);
}

} // namespace

uint32_t finestMipFromLod(float lodBeforeBias, float bias, uint32_t mipCount) {
    float lod = lodBeforeBias + bias;
    if (!(lod > 0.0f)) return 0;
    return std::min(uint32_t(lod), mipCount - 1);
}

CoarseInstanceView viewInstance(const CoarseVisitPolicy& policy, const GpuScene& scene,
                                const CameraView& camera, const std::array<glm::vec4, 6>& planes,
                                uint32_t instance) {
    CoarseInstanceView out;
    const gpu::GpuInstance& inst = scene.instanceInfo[instance];
    const ShadelMeshInfo& mesh = scene.shadelMeshes[inst.mesh];
    glm::vec3 margin = (inst.worldMax - inst.worldMin) * policy.frustumMargin;
    // Transparent surfaces are shaded in shadel space too and reconstructed into the WBOIT
    // targets (render/oit); the sorted reference keeps them forward.
    bool blended = inst.material < scene.materialInfo.size() &&
                   (scene.materialInfo[inst.material].flags & MATERIAL_ALPHA_BLEND) != 0u;
    // Transmissive surfaces are drawn forward after the opaque scene (render/transmission).
    bool transmissive = inst.material < scene.materialInfo.size() &&
                        (scene.materialInfo[inst.material].flags & MATERIAL_TRANSMISSION) != 0u;
    out.inFrustum = mesh.mipCount > 0 && !(blended && policy.blendedForward) && !transmissive &&
                    boxVisible(planes, inst.worldMin - margin, inst.worldMax + margin);
    if (!out.inFrustum) return out;
    // Hybrid: an object a few pixels across would still shade whole chunks at its coarsest MIP;
    // forward is cheaper.
    out.small = policy.forwardBelowPixels > 0.0f &&
                projectedDiameter(
                    camera, policy.viewportHeight, 0.5f * (inst.worldMin + inst.worldMax),
                    0.5f * glm::length(inst.worldMax - inst.worldMin)) < policy.forwardBelowPixels;
    if (out.small) return out; // drawn forward: no MIP needed (most of a wide world's instances)
    out.lodBeforeBias = policy.sheetAllMips
                            ? kNeedsMip0
                            : footprintLod(camera, policy.viewportHeight, inst, mesh,
                                           inst.worldMin - margin, inst.worldMax + margin);
    return out;
}

void visitCoarse(const CoarseVisitPolicy& policy, const GpuScene& scene, const InstanceGrid& grid,
                 const CameraView& camera, CoarseVisit& out) {
    out.camera = camera;
    out.instances.clear();
    out.views.clear();
    // The frame constants' viewProj (renderer.cpp makeFrameConstants), by the same expression.
    glm::mat4 viewProj = camera.proj * camera.view;
    auto planes = frustumPlanes(viewProj);
    Aabb frustumBox;
    glm::mat4 invViewProj = glm::inverse(viewProj);
    for (int c = 0; c < 8; ++c) {
        glm::vec4 p =
            invViewProj * glm::vec4((c & 1) ? 1 : -1, (c & 2) ? 1 : -1, (c & 4) ? 1 : 0, 1);
        frustumBox.extend(glm::vec3(p) / p.w);
    }
    grid.query(frustumBox, out.instances);
    out.views.resize(out.instances.size());
    // The instances are scattered over the world's GpuInstance array (160 MB at 1M): fetching a
    // few ahead overlaps their cache and TLB misses.
    constexpr size_t kAhead = 8;
    for (size_t v = 0; v < out.instances.size(); ++v) {
        if (v + kAhead < out.instances.size()) {
            const auto* inst =
                reinterpret_cast<const char*>(&scene.instanceInfo[out.instances[v + kAhead]]);
            __builtin_prefetch(inst);
            __builtin_prefetch(inst + offsetof(gpu::GpuInstance, worldMin));
            __builtin_prefetch(inst + sizeof(gpu::GpuInstance) - 1);
        }
        out.views[v] = viewInstance(policy, scene, camera, planes, out.instances[v]);
    }
}

bool sameVisitCamera(const CameraView& a, const CameraView& b) {
    return std::memcmp(&a.view, &b.view, sizeof(a.view)) == 0 &&
           std::memcmp(&a.proj, &b.proj, sizeof(a.proj)) == 0 &&
           std::memcmp(&a.position, &b.position, sizeof(a.position)) == 0 && a.znear == b.znear;
}

} // namespace shadel
