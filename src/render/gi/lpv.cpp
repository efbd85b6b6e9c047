#include "render/gi/lpv.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "core/log.h"
#include "gi/gi_types.h"
#include "render/forward/forward_passes.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace shadel {

namespace {

constexpr uint32_t kRsmSize = 256;
constexpr uint32_t kCells = GI_GRID * GI_GRID * GI_GRID;
constexpr VkFormat kRsmFormats[3] = {VK_FORMAT_R32G32B32A32_SFLOAT,  // position
                                     VK_FORMAT_R16G16B16A16_SFLOAT,  // normal + area
                                     VK_FORMAT_R16G16B16A16_SFLOAT}; // flux

struct RsmPush { // shaders/gi/rsm_push.glsl
    glm::mat4 viewProj;
    uint64_t frame;
    uint32_t light;
    float texelArea;
    float texelSolidAngle;
};

struct InjectPush { // shaders/gi/inject.comp
    uint64_t gi;
    uint64_t inject[GI_MAX_VOLUMES];
    uint32_t positionSlot, normalSlot, fluxSlot, size;
    uint32_t cascadeMask; // cascades injected this frame
};

struct PropagatePush { // shaders/gi/propagate.comp
    uint64_t inject, source, target, accum, geometry, axial, blockers, portals, cells;
    glm::vec3 origin;
    float cellSize;
    uint32_t blockerCount;
    uint32_t mode;
};

// One light's reflective shadow map: three colour targets and a depth buffer.
struct Rsm {
    TextureHandle targets[3], depth;
    RenderTargetView targetViews[3];
    TextureReadView readViews[3];
    DepthTargetView depthView;
    uint32_t light = 0xFFFFFFFFu; // light index, 0xFFFFFFFF = the sun
    glm::mat4 viewProj{1.0f};
    float texelArea = 0.0f, texelSolidAngle = 0.0f;
    glm::vec3 lightPosition{0.0f}, lightDirection{0.0f}; // the spot's view the map was drawn for
};

struct CascadeBuffers {
    BufferHandle inject;       // int[GI_INJECT_INTS] per cell
    BufferHandle light[2];     // ping-pong propagation steps, vec4[3] per cell
    BufferHandle accum;        // vec4[3] per cell (the apply reads it)
    BufferHandle geometry;     // vec4 per cell
    BufferHandle axial;        // vec4 per cell: blocker coverage of its -x, -y, -z faces
    BufferHandle blockerCells; // uint64 blocker mask per macro-cell (host-visible)
};

} // namespace

struct GiState {
    std::vector<Rsm> rsms;
    // The volumes, in the order of GiFrame::cascades: local volumes, then the camera cascades.
    CascadeBuffers cascades[GI_MAX_VOLUMES];
    uint32_t localCount = 0; // volumes [0, localCount) are local, the next GI_CASCADES cascades
    std::vector<GiLocalVolume> locals;
    uint64_t localUpdates = 0; // injections + propagations of a local volume over the run
    BufferHandle frame;        // host-visible GiFrame
    BufferHandle blockers;     // GpuGiBlocker[], when there are any
    BufferHandle portals;      // vec4[] (min u, min v, max u, max v), when there are any
    uint32_t blockerCount = 0;
    std::vector<GiBlocker> blockerList;
    uint64_t blockerCellPairs = 0; // (macro-cell, blocker) pairs of the cascades in use
    uint64_t cascadePairs[GI_MAX_VOLUMES] = {};
    gpu::GiFrame constants{};
    float baseCellSize = 1.0f;
    Pipeline rsmPass, inject, propagate;
    // What is still valid from earlier frames. The lights' views are fixed (the sun's is fitted
    // to the scene, spots do not move for GI), so the RSMs are drawn once; a cascade is injected
    // and propagated again only when it moved (snapped to a new cell) since its last update.
    bool rsmsDrawn = false;
    bool cascadeValid[GI_MAX_VOLUMES] = {};
    glm::vec3 cascadeOrigin[GI_MAX_VOLUMES] = {}; // where its light was computed (the apply's too)
    uint64_t cascadeUpdatedFrame[GI_MAX_VOLUMES] = {};

    uint32_t volumeCount() const { return localCount + GI_CASCADES; }
    uint32_t dirtyMask = 0; // cascades updated this frame
    uint64_t frames = 0, cascadeUpdates = 0, rsmRenders = 0;
};

void GiStateDeleter::operator()(GiState* state) const {
    delete state;
}

static void createRsmTargets(Gpu& gpu, Rsm& rsm, uint32_t index) {
    static const char* names[3] = {"position", "normal", "flux"};
    for (int k = 0; k < 3; ++k) {
        TextureDesc d;
        d.name = "gi.rsm" + std::to_string(index) + "." + names[k];
        d.format = kRsmFormats[k];
        d.width = d.height = kRsmSize;
        d.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
        rsm.targets[k] = createTexture(gpu, d);
        if (!rsm.targets[k])
            throw DeviceError("out of GPU memory for the GI reflective shadow maps");
        rsm.targetViews[k] = createRenderTargetView(gpu, rsm.targets[k]);
        rsm.readViews[k] = createReadView(gpu, rsm.targets[k]);
    }
    TextureDesc d;
    d.name = "gi.rsm" + std::to_string(index) + ".depth";
    d.format = VK_FORMAT_D32_SFLOAT;
    d.width = d.height = kRsmSize;
    d.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
    rsm.depth = createTexture(gpu, d);
    if (!rsm.depth) throw DeviceError("out of GPU memory for the GI reflective shadow maps");
    rsm.depthView = createDepthTargetView(gpu, rsm.depth);
}

// The spot's perspective view: its cone (outer angle, from the shading constants) fills the map.
static void spotView(const gpu::GpuLight& l, Rsm& rsm) {
    float cosOuter = std::clamp(-l.spotOffset / std::max(l.spotScale, 1e-6f), 0.05f, 0.9999f);
    float fov = std::min(2.0f * std::acos(cosOuter), glm::radians(170.0f));
    glm::vec3 dir = glm::normalize(l.direction);
    glm::vec3 up = std::abs(dir.y) > 0.99f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    float range = l.range > 0.0f ? l.range : 200.0f;
    glm::mat4 view = glm::lookAt(l.position, l.position + dir, up);
    glm::mat4 proj = glm::perspectiveRH_ZO(fov, 1.0f, 0.05f, range);
    rsm.viewProj = proj * view;
    float texel = 2.0f * std::tan(fov * 0.5f) / float(kRsmSize);
    rsm.texelSolidAngle = texel * texel; // at the centre; the shader applies cos^3
    rsm.lightPosition = l.position;
    rsm.lightDirection = l.direction;
}

GiStatePtr createGi(Renderer& r, const GpuScene& scene) {
    Gpu& gpu = *r.gpu;
    GiStatePtr gi(new GiState);
    if (scene.sunCastsShadow && glm::dot(scene.sunColor, scene.sunColor) > 0.0f) {
        gi->rsms.emplace_back();
        gi->rsms.back().light = 0xFFFFFFFFu;
    }
    for (uint32_t i = 0; i < scene.lightInfo.size() && gi->rsms.size() < GI_MAX_RSMS; ++i)
        if (scene.lightInfo[i].type == LIGHT_SPOT && i < scene.lightCastsShadow.size() &&
            scene.lightCastsShadow[i]) {
            gi->rsms.emplace_back();
            gi->rsms.back().light = i;
            spotView(scene.lightInfo[i], gi->rsms.back());
        }
    for (uint32_t i = 0; i < gi->rsms.size(); ++i) createRsmTargets(gpu, gi->rsms[i], i);

    gi->locals = r.settings.giLocalVolumes;
    if (gi->locals.size() > GI_MAX_LOCAL_VOLUMES) gi->locals.resize(GI_MAX_LOCAL_VOLUMES);
    gi->localCount = uint32_t(gi->locals.size());
    for (uint32_t c = 0; c < gi->volumeCount(); ++c) {
        CascadeBuffers& b = gi->cascades[c];
        std::string prefix = c < gi->localCount
                                 ? "gi.local." + gi->locals[c].name + "."
                                 : "gi.cascade" + std::to_string(c - gi->localCount) + ".";
        b.inject = createBuffer(gpu, {prefix + "inject", VkDeviceSize(kCells) * GI_INJECT_INTS * 4,
                                      VK_BUFFER_USAGE_TRANSFER_DST_BIT});
        for (int k = 0; k < 2; ++k)
            b.light[k] =
                createBuffer(gpu, {prefix + (k ? "lightB" : "lightA"), VkDeviceSize(kCells) * 48});
        b.accum = createBuffer(gpu, {prefix + "radiance", VkDeviceSize(kCells) * 48});
        b.geometry = createBuffer(gpu, {prefix + "geometry", VkDeviceSize(kCells) * 16});
        b.axial = createBuffer(gpu, {prefix + "axialOcclusion", VkDeviceSize(kCells) * 16});
        if (!b.inject || !b.light[0] || !b.light[1] || !b.accum || !b.geometry || !b.axial)
            throw DeviceError("out of GPU memory for the GI volumes");
    }
    gi->frame = createBuffer(gpu, {"gi.frame", sizeof(gpu::GiFrame), 0, MemoryKind::Upload});
    if (!gi->frame) throw DeviceError("out of GPU memory for the GI constants");
    const std::vector<GiBlocker>& blockers = r.settings.giBlockers;
    if (blockers.size() > GI_MAX_BLOCKERS)
        throw InputError(
            format("%zu GI light blockers: at most %u", blockers.size(), GI_MAX_BLOCKERS));
    if (!blockers.empty()) {
        std::vector<gpu::GpuGiBlocker> packed;
        std::vector<glm::vec4> portals;
        for (const GiBlocker& b : blockers) {
            uint32_t count = uint32_t(std::min<size_t>(b.portals.size(), 0xFFFF));
            if (portals.size() + count > 0xFFFF)
                throw InputError("GI light blockers: more than 65535 portals in all");
            packed.push_back({b.center, b.halfSize.x, glm::normalize(b.axisU), b.halfSize.y,
                              glm::normalize(b.axisV), uint32_t(portals.size()) | (count << 16)});
            portals.insert(portals.end(), b.portals.begin(), b.portals.begin() + count);
        }
        gi->blockers = createBuffer(
            gpu, {"gi.blockers", packed.size() * sizeof(packed[0]), 0, MemoryKind::Upload});
        if (!gi->blockers) throw DeviceError("out of GPU memory for the GI blockers");
        std::memcpy(mapped(gpu, gi->blockers), packed.data(), packed.size() * sizeof(packed[0]));
        if (!portals.empty()) {
            gi->portals =
                createBuffer(gpu, {"gi.blockerPortals", portals.size() * sizeof(glm::vec4), 0,
                                   MemoryKind::Upload});
            if (!gi->portals) throw DeviceError("out of GPU memory for the GI blocker portals");
            std::memcpy(mapped(gpu, gi->portals), portals.data(),
                        portals.size() * sizeof(glm::vec4));
        }
        gi->blockerCount = uint32_t(packed.size());
        gi->blockerList = blockers;
        for (uint32_t c = 0; c < gi->volumeCount(); ++c) {
            gi->cascades[c].blockerCells =
                createBuffer(gpu, {"gi.volume" + std::to_string(c) + ".blockerCells",
                                   VkDeviceSize(GI_MACRO_GRID * GI_MACRO_GRID * GI_MACRO_GRID) * 8,
                                   0, MemoryKind::Upload});
            if (!gi->cascades[c].blockerCells)
                throw DeviceError("out of GPU memory for the GI blocker cells");
        }
    }

    // Cascade 0's cells: a room-sized scene fits in cascade 0 (8 steps carry light a quarter of
    // the way across it); larger scenes get 1-unit cells (a metre in the built-in scenes), but
    // never so small that the coarsest cascade (4x the cell) misses most of the scene.
    Aabb bounds = scene.bounds.valid() ? scene.bounds : Aabb{glm::vec3(-1), glm::vec3(1)};
    glm::vec3 e = bounds.extent();
    float extent = std::max(std::max(e.x, std::max(e.y, e.z)), 1e-3f);
    gi->baseCellSize =
        std::max(std::min(2.0f * extent / float(GI_GRID), 1.0f), extent / (4.0f * GI_GRID));

    GraphicsPipelineDesc rsm;
    rsm.name = "giReflectiveShadowMap";
    rsm.vertexShader = "gi_rsm.vert.spv";
    rsm.fragmentShader = "gi_rsm.frag.spv";
    rsm.colorFormats = {kRsmFormats[0], kRsmFormats[1], kRsmFormats[2]};
    rsm.depthFormat = VK_FORMAT_D32_SFLOAT;
    rsm.depthCompare = VK_COMPARE_OP_LESS; // standard Z: the light's nearest surface
    rsm.cullMode = VK_CULL_MODE_NONE;
    rsm.depthClamp = true; // casters behind the sun's near plane still land in the map
    gi->rsmPass = createGraphicsPipeline(gpu, rsm);
    gi->inject = createComputePipeline(gpu, "giInject", "gi_inject.comp.spv");
    gi->propagate = createComputePipeline(gpu, "giPropagate", "gi_propagate.comp.spv");
    return gi;
}

void destroyGi(Renderer& r, GiStatePtr& state) {
    if (!state) return;
    Gpu& gpu = *r.gpu;
    for (Rsm& rsm : state->rsms) {
        for (int k = 0; k < 3; ++k) {
            destroy(gpu, rsm.targetViews[k]);
            destroy(gpu, rsm.readViews[k]);
            destroy(gpu, rsm.targets[k]);
        }
        destroy(gpu, rsm.depthView);
        destroy(gpu, rsm.depth);
    }
    for (CascadeBuffers& b : state->cascades)
        for (BufferHandle h :
             {b.inject, b.light[0], b.light[1], b.accum, b.geometry, b.axial, b.blockerCells})
            if (h) destroy(gpu, h);
    destroy(gpu, state->frame);
    if (state->blockers) destroy(gpu, state->blockers);
    if (state->portals) destroy(gpu, state->portals);
    destroy(gpu, state->rsmPass);
    destroy(gpu, state->inject);
    destroy(gpu, state->propagate);
    state.reset();
}

std::vector<GiLocalVolume> giLocalVolumesOf(const Scene& scene, size_t& dropped) {
    std::vector<GiLocalVolume> out;
    dropped = 0;
    for (const GiVolume& v : scene.giVolumes) {
        if (out.size() == GI_MAX_LOCAL_VOLUMES) {
            ++dropped;
            continue;
        }
        out.push_back({v.name, v.box.min, v.box.max});
    }
    return out;
}

std::vector<GiBlocker> giBlockersOf(const Scene& scene) {
    std::vector<GiBlocker> out;
    for (const LightBlocker& b : scene.blockers) {
        GiBlocker g{b.center, b.axisU, b.axisV, b.halfSize, {}};
        for (const LightBlocker::Portal& p : b.portals)
            g.portals.push_back({p.min.x, p.min.y, p.max.x, p.max.y});
        out.push_back(std::move(g));
    }
    return out;
}

// Whether blocker b can cut a segment inside the box [lo, hi]: its plane crosses the box and
// its rectangle's bounds meet it (conservative: portals are not subtracted).
static bool blockerMeetsBox(const GiBlocker& b, glm::vec3 lo, glm::vec3 hi) {
    glm::vec3 u = glm::normalize(b.axisU), v = glm::normalize(b.axisV);
    glm::vec3 n = glm::cross(u, v);
    glm::vec3 centre = 0.5f * (lo + hi), half = 0.5f * (hi - lo);
    if (std::abs(glm::dot(centre - b.center, n)) > glm::dot(half, glm::abs(n))) return false;
    glm::vec3 reach = glm::abs(u) * b.halfSize.x + glm::abs(v) * b.halfSize.y;
    return glm::all(glm::lessThanEqual(b.center - reach, hi)) &&
           glm::all(glm::greaterThanEqual(b.center + reach, lo));
}

// Macro-cell culling of the blockers (against 4x4x4-cell macro-cells):
// per macro-cell of a cascade at its origin, the blockers a tap segment starting there can
// cross. Segments end within one cell (and a half, the apply's offset along the normal).
static uint64_t fillBlockerCells(const GiState& gi, glm::vec3 origin, float cell, uint64_t* cells) {
    uint64_t pairs = 0;
    float macro = cell * float(GI_MACRO);
    for (uint32_t z = 0; z < GI_MACRO_GRID; ++z)
        for (uint32_t y = 0; y < GI_MACRO_GRID; ++y)
            for (uint32_t x = 0; x < GI_MACRO_GRID; ++x) {
                glm::vec3 lo = origin + glm::vec3(x, y, z) * macro - 1.5f * cell;
                glm::vec3 hi = origin + glm::vec3(x + 1, y + 1, z + 1) * macro + 1.5f * cell;
                uint64_t mask = 0;
                for (uint32_t k = 0; k < gi.blockerList.size(); ++k)
                    if (blockerMeetsBox(gi.blockerList[k], lo, hi)) mask |= 1ull << k;
                cells[(z * GI_MACRO_GRID + y) * GI_MACRO_GRID + x] = mask;
                pairs += uint64_t(__builtin_popcountll(mask));
            }
    return pairs;
}

void prepareGiFrame(Renderer& r, const GpuScene& scene, const CameraView& camera,
                    gpu::FrameConstants& constants) {
    (void)scene;
    GiState& gi = *r.gi;
    gpu::GiFrame& g = gi.constants;
    g = {};
    gi.dirtyMask = 0;
    gi.frames++;
    // Live lights (animated or edited): a spot that moved needs its RSM again, and every
    // cascade its light.
    bool lightsMoved = false;
    if (!r.lightsLastFrame.empty())
        for (Rsm& rsm : gi.rsms) {
            if (rsm.light == 0xFFFFFFFFu || rsm.light >= r.lightsLastFrame.size()) continue;
            const gpu::GpuLight& l = r.lightsLastFrame[rsm.light]; // this frame's lights
            if (l.position == rsm.lightPosition && l.direction == rsm.lightDirection) continue;
            spotView(l, rsm);
            lightsMoved = true;
        }
    if (lightsMoved) {
        gi.rsmsDrawn = false;
        for (bool& valid : gi.cascadeValid) valid = false;
    }
    const uint32_t volumes = gi.volumeCount(), L = gi.localCount;
    g.cascadeCount = volumes;
    g.intensity = r.settings.giIntensity;
    g.blockerCount = gi.blockerCount;
    g.blockers = gi.blockers ? address(*r.gpu, gi.blockers) : 0;
    g.portals = gi.portals ? address(*r.gpu, gi.portals) : 0;
    g.blockerCells = r.settings.giBlockerCells ? 1u : 0u;
    glm::vec3 wanted[GI_MAX_VOLUMES];
    float cellSize[GI_MAX_VOLUMES];
    uint32_t moved = 0;
    bool allValid = true;
    for (uint32_t v = 0; v < volumes; ++v) {
        if (v < L) { // a local volume: a fixed cubic grid centred on its box
            const GiLocalVolume& lv = gi.locals[v];
            glm::vec3 e = lv.max - lv.min;
            cellSize[v] = std::max(std::max(e.x, std::max(e.y, e.z)), 1e-3f) / float(GI_GRID);
            wanted[v] = 0.5f * (lv.min + lv.max) - glm::vec3(0.5f * float(GI_GRID) * cellSize[v]);
        } else {
            float cell = gi.baseCellSize * float(1u << (v - L));
            // Snapped: the grid moves in whole cells, so a surface keeps its cell (and its
            // light) while the camera moves; unsnapped (a debug option) it slides and swims.
            glm::vec3 corner = camera.position / cell - float(GI_GRID / 2);
            if (r.settings.giSnap) corner = glm::floor(corner);
            wanted[v] = corner * cell;
            cellSize[v] = cell;
        }
        if (!gi.cascadeValid[v] || gi.cascadeOrigin[v] != wanted[v]) moved |= 1u << v;
        allValid = allValid && gi.cascadeValid[v];
    }
    // Time slicing: after the first frame at most one cascade is injected and propagated per
    // frame, the one waiting longest; the others keep the origin their light was computed at
    // (a few cells behind the camera at most, inside their 16-cell margin). Local volumes never
    // move: they are updated with everything else on the first frame and when lights change.
    // Without snapping (the debug baseline) every cascade follows the camera every frame.
    if (!allValid || !r.settings.giSnap) {
        gi.dirtyMask = moved;
    } else if (moved) {
        uint32_t pick = volumes;
        for (uint32_t c = L; c < volumes; ++c)
            if ((moved & (1u << c)) &&
                (pick == volumes || gi.cascadeUpdatedFrame[c] < gi.cascadeUpdatedFrame[pick]))
                pick = c;
        if (pick < volumes) gi.dirtyMask = 1u << pick;
    }
    for (uint32_t c = 0; c < volumes; ++c) {
        if (gi.dirtyMask & (1u << c)) {
            gi.cascadeOrigin[c] = wanted[c];
            gi.cascadeValid[c] = true;
            gi.cascadeUpdatedFrame[c] = gi.frames;
            if (c < L) gi.localUpdates++;
        }
        gpu::GiCascade& gc = g.cascades[c];
        gc.origin = gi.cascadeOrigin[c];
        gc.cellSize = cellSize[c];
        gc.radiance = address(*r.gpu, gi.cascades[c].accum);
        gc.geometry = address(*r.gpu, gi.cascades[c].geometry);
        if (gi.cascades[c].blockerCells) {
            // Recomputed where the cascade's light is (its origin moves only when updated).
            if (gi.dirtyMask & (1u << c)) {
                auto* cells = static_cast<uint64_t*>(mapped(*r.gpu, gi.cascades[c].blockerCells));
                gi.cascadePairs[c] = fillBlockerCells(gi, gc.origin, gc.cellSize, cells);
            }
            gc.blockerCells = address(*r.gpu, gi.cascades[c].blockerCells);
        }
    }
    gi.blockerCellPairs = 0;
    for (uint64_t pairs : gi.cascadePairs) gi.blockerCellPairs += pairs;
    std::memcpy(mapped(*r.gpu, gi.frame), &g, sizeof(g));
    for (Rsm& rsm : gi.rsms)
        if (rsm.light == 0xFFFFFFFFu) {
            rsm.viewProj = constants.sunViewProj;
            // The shadow map's texel is 2 r / shadowMapSize; the RSM spans the same square.
            float texel = constants.shadowTexelSize * float(r.settings.shadowMapSize) / kRsmSize;
            rsm.texelArea = texel * texel;
        }
    constants.gi = address(*r.gpu, gi.frame);
}

void recordGiReflectiveShadowMaps(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    GiState& gi = *r.gi;
    if (gi.rsmsDrawn) return;
    gi.rsmsDrawn = true;
    gi.rsmRenders++;
    for (Rsm& rsm : gi.rsms) {
        for (int k = 0; k < 3; ++k)
            imageBarrier(cmd, vkImage(gpu, rsm.targets[k]), VK_IMAGE_ASPECT_COLOR_BIT,
                         VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                         VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, 0,
                         VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                         VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
        imageBarrier(cmd, vkImage(gpu, rsm.depth), VK_IMAGE_ASPECT_DEPTH_BIT,
                     VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                     VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT, 0,
                     VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                         VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
                         VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
        VkRenderingAttachmentInfo colors[3];
        for (int k = 0; k < 3; ++k) {
            colors[k] = {VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
            colors[k].imageView = vkView(gpu, rsm.targetViews[k]);
            colors[k].imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
            colors[k].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR; // w = 0: no surface
            colors[k].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
            colors[k].clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}};
        }
        VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        depth.imageView = vkView(gpu, rsm.depthView);
        depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
        depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
        depth.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
        depth.clearValue.depthStencil = {1.0f, 0};
        VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
        ri.renderArea = {{0, 0}, {kRsmSize, kRsmSize}};
        ri.layerCount = 1;
        ri.colorAttachmentCount = 3;
        ri.pColorAttachments = colors;
        ri.pDepthAttachment = &depth;
        vkCmdBeginRendering(cmd, &ri);
        bind(gpu, cmd, gi.rsmPass);
        VkViewport vp{0, 0, float(kRsmSize), float(kRsmSize), 0, 1};
        VkRect2D scissor{{0, 0}, {kRsmSize, kRsmSize}};
        vkCmdSetViewport(cmd, 0, 1, &vp);
        vkCmdSetScissor(cmd, 0, 1, &scissor);
        pushConstants(gpu, cmd,
                      RsmPush{rsm.viewProj, frame, rsm.light, rsm.texelArea, rsm.texelSolidAngle});
        vkCmdBindIndexBuffer(cmd, vkBuffer(gpu, r.sceneIndices), 0, VK_INDEX_TYPE_UINT32);
        // The sun's shadow list: its volume is fitted to the whole scene, so it also holds
        // every opaque instance a spot inside the scene can see (the GPU clips the rest).
        drawSunShadowList(r, cmd);
        vkCmdEndRendering(cmd);
        for (int k = 0; k < 3; ++k)
            imageBarrier(
                cmd, vkImage(gpu, rsm.targets[k]), VK_IMAGE_ASPECT_COLOR_BIT,
                VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
    }
}

void recordGiInjection(Renderer& r, VkCommandBuffer cmd) {
    Gpu& gpu = *r.gpu;
    GiState& gi = *r.gi;
    if (!gi.dirtyMask) return;
    for (uint32_t c = 0; c < gi.volumeCount(); ++c)
        if (gi.dirtyMask & (1u << c)) {
            vkCmdFillBuffer(cmd, vkBuffer(gpu, gi.cascades[c].inject), 0, VK_WHOLE_SIZE, 0);
            if (c >= gi.localCount) gi.cascadeUpdates++; // (local volumes: localUpdates)
        }
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    bind(gpu, cmd, gi.inject);
    for (Rsm& rsm : gi.rsms) {
        InjectPush push{};
        push.gi = address(gpu, gi.frame);
        for (uint32_t c = 0; c < gi.volumeCount(); ++c)
            push.inject[c] = address(gpu, gi.cascades[c].inject);
        push.positionSlot = slot(gpu, rsm.readViews[0]).value;
        push.normalSlot = slot(gpu, rsm.readViews[1]).value;
        push.fluxSlot = slot(gpu, rsm.readViews[2]).value;
        push.size = kRsmSize;
        push.cascadeMask = gi.dirtyMask;
        pushConstants(gpu, cmd, push);
        vkCmdDispatch(cmd, kRsmSize / 8, kRsmSize / 8, 1);
    }
    // Resolve: fixed-point sums into the first propagation source, the accumulated light and
    // the geometry volume.
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    bind(gpu, cmd, gi.propagate);
    for (uint32_t c = 0; c < gi.volumeCount(); ++c) {
        if (!(gi.dirtyMask & (1u << c))) continue;
        CascadeBuffers& b = gi.cascades[c];
        PropagatePush push{};
        push.inject = address(gpu, b.inject);
        push.target = address(gpu, b.light[0]);
        push.accum = address(gpu, b.accum);
        push.geometry = address(gpu, b.geometry);
        push.axial = address(gpu, b.axial);
        push.blockers = gi.blockers ? address(gpu, gi.blockers) : 0;
        push.portals = gi.portals ? address(gpu, gi.portals) : 0;
        push.cells = gi.cascades[c].blockerCells && r.settings.giBlockerCells
                         ? address(gpu, gi.cascades[c].blockerCells)
                         : 0;
        push.origin = gi.constants.cascades[c].origin;
        push.cellSize = gi.constants.cascades[c].cellSize;
        push.blockerCount = gi.blockerCount;
        push.mode = 0;
        pushConstants(gpu, cmd, push);
        vkCmdDispatch(cmd, GI_GRID / 4, GI_GRID / 4, GI_GRID / 4);
    }
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
}

// Propagation steps of volume v. Light crosses one cell per step, so the cascades' few steps
// (--gi-iterations, every time one moves) carry it a few metres. A local volume is propagated
// once (and again only when the lights change), so it runs until light has crossed the whole
// grid: GI_GRID steps. On builtin:cornell (its room volume has cells half as wide as cascade
// 0's) the floor by the red wall reads red/green 1.10 after 16 steps and 1.39 after 32; the
// cascades alone give 1.28 after 8.
static uint32_t propagationSteps(const GiState& gi, uint32_t v, uint32_t iterations) {
    // (--gi-iterations 0, injection only, holds for every volume.)
    return v < gi.localCount && iterations > 0 ? std::max(iterations, GI_GRID) : iterations;
}

void recordGiPropagation(Renderer& r, VkCommandBuffer cmd) {
    Gpu& gpu = *r.gpu;
    GiState& gi = *r.gi;
    if (!gi.dirtyMask) return;
    bind(gpu, cmd, gi.propagate);
    uint32_t steps = 0;
    for (uint32_t c = 0; c < gi.volumeCount(); ++c)
        if (gi.dirtyMask & (1u << c))
            steps = std::max(steps, propagationSteps(gi, c, r.settings.giIterations));
    for (uint32_t step = 0; step < steps; ++step) {
        // The volumes are independent: one barrier per step serves them all.
        for (uint32_t c = 0; c < gi.volumeCount(); ++c) {
            if (!(gi.dirtyMask & (1u << c))) continue;
            if (step >= propagationSteps(gi, c, r.settings.giIterations)) continue;
            CascadeBuffers& b = gi.cascades[c];
            PropagatePush push{};
            push.source = address(gpu, b.light[step & 1]);
            push.target = address(gpu, b.light[(step + 1) & 1]);
            push.accum = address(gpu, b.accum);
            push.geometry = address(gpu, b.geometry);
            push.axial = address(gpu, b.axial);
            push.mode = 1;
            pushConstants(gpu, cmd, push);
            vkCmdDispatch(cmd, GI_GRID / 4, GI_GRID / 4, GI_GRID / 4);
        }
        memoryBarrier(
            cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
            VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
            VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    }
    if (steps == 0)
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
}

void giStats(const Renderer& r, nlohmann::json& stats) {
    const GiState& gi = *r.gi;
    nlohmann::json cascades = nlohmann::json::array(), locals = nlohmann::json::array();
    for (uint32_t c = 0; c < gi.localCount; ++c) {
        const gpu::GiCascade& gc = gi.constants.cascades[c];
        locals.push_back({{"name", gi.locals[c].name},
                          {"propagation_steps", propagationSteps(gi, c, r.settings.giIterations)},
                          {"cell_size", gc.cellSize},
                          {"extent", gc.cellSize * GI_GRID},
                          {"origin", {gc.origin.x, gc.origin.y, gc.origin.z}},
                          {"cells", kCells}});
    }
    for (uint32_t c = gi.localCount; c < gi.volumeCount(); ++c) {
        const gpu::GiCascade& gc = gi.constants.cascades[c];
        cascades.push_back({{"cell_size", gc.cellSize},
                            {"extent", gc.cellSize * GI_GRID},
                            {"origin", {gc.origin.x, gc.origin.y, gc.origin.z}},
                            {"cells", kCells}});
    }
    stats["gi"] = {{"mode", "lpv"},
                   {"cascades", cascades},
                   {"local_volumes", locals},
                   // Injections + propagations of a local volume (the first frame's, and one
                   // per change of the lights): they do not follow the camera.
                   {"local_volume_updates", gi.localUpdates},
                   {"grid", GI_GRID},
                   {"cells", kCells * gi.volumeCount()},
                   {"iterations", r.settings.giIterations},
                   {"snap", r.settings.giSnap},
                   {"blockers", gi.blockerCount},
                   {"portals",
                    [&] {
                        size_t n = 0;
                        for (const GiBlocker& b : gi.blockerList) n += b.portals.size();
                        return n;
                    }()},
                   {"blocker_cells", r.settings.giBlockerCells},
                   // Blockers a macro-cell's taps test, on average (all blockers without culling).
                   {"blockers_per_macro_cell",
                    double(gi.blockerCellPairs) /
                        double(gi.volumeCount() * GI_MACRO_GRID * GI_MACRO_GRID * GI_MACRO_GRID)},
                   {"reflective_shadow_maps", gi.rsms.size()},
                   {"rsm_renders", gi.rsmRenders},
                   // Injections + propagations of one cascade over the run (a cascade is
                   // updated when it snaps to a new cell; frames x 3 would be every frame).
                   {"cascade_updates", gi.cascadeUpdates},
                   {"frames", gi.frames},
                   {"rsm_size", kRsmSize}};
}

} // namespace shadel
