// The CPU side of a decoupled frame: which instances are shaded in shadel space, their sheet
// rects, rates and reuse, written into their GPU entries and the frame's ShadelFrame.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "render/gpu_scene.h"
#include "render/shadel/decoupled_state.h"
#include "render/shadel/shadel_sheet.h"
#include "render/shadel/texture_rate.h"

namespace shadel {

namespace {

// How far the view of a carried-over chunk may turn before its specular visibly lags
// (GpuShadelObject::viewDriftCos holds its cosine, checked per chunk: shadel.glsl chunkViewTurned).
// Specular and Fresnel follow the view direction, and a specular lobe is about roughness^2 radians
// wide, so the direction from the chunk to the camera may turn by about that much. Only the
// specular part lags, and a dielectric reflects about F0 = 4% of the light specularly (metals all
// of it): the turn a lag of the whole lobe's width costs is scaled by that share (doubled for
// Fresnel's rise towards grazing angles), so a rough dielectric is carried over far longer than a
// polished metal. Roughness textures only lower the factor's roughness, so glossier texels than the
// factor can lag somewhat more.
// The specular share is measured against the darkest albedo channel: a saturated base colour
// lets a coloured light's specular dominate the channels it barely reflects (builtin:many's
// green trees under the pink street light: its red and blue are mostly specular, and their
// carried chunks lagged the view far enough to drop a frame to 29 dB against reuse off). Share =
// the GGX peak's specular (F0 = 4%, D = 1 / (pi alpha^2), over 4) against that channel's Lambert
// diffuse. The turn allowed, in lobe widths, is SPECULAR_SHARE_TOLERANCE / share within
// [SPECULAR_SHARE_MIN_GAIN, SPECULAR_SHARE_MAX_GAIN]: the lag a turn leaves is about share x
// turn / lobe, so the tolerance is roughly the error allowed in the darkest channel. A rough
// light-coloured dielectric (share ~8%) keeps the cap, the trees (share 0.25) 0.6 lobes.
// The tolerance, the least gain and the cap of the gain are chosen from sweeps of reuse
// fraction against the worst frame's PSNR (reuse on vs off) on builtin:default and builtin:many;
// docs/decoupled/README.md has them.
constexpr float SPECULAR_SHARE_MIN_GAIN = 0.5f;
constexpr float SPECULAR_SHARE_MAX_GAIN = 2.0f;
constexpr float SPECULAR_SHARE_TOLERANCE = 0.15f;
constexpr float SPECULAR_SHARE_MIN_GAIN_ENVIRONMENT = 0.25f;

// Under an environment the specular reflects light from every direction, not only the lights'
// peaks: its share is then the reflected environment (Fresnel averaged over the hemisphere,
// F0 + (1 - F0) / 21, of about the light the diffuse receives) against the darkest channel's
// diffuse, whatever the roughness; the larger of the two shares sets the tolerance, and the
// gain may fall to SPECULAR_SHARE_MIN_GAIN_ENVIRONMENT: a grazing view of a saturated material
// reflects mostly the environment, which a turn of half a lobe already shows at its rim.
float viewDriftLimitFor(float roughness, float metallic, glm::vec3 baseColor, bool environment) {
    constexpr float kPi = 3.14159265f;
    float lobeWidth = std::clamp(roughness * roughness, 0.01f, 0.4f);
    float specularPeak = 0.04f / (4.0f * kPi * lobeWidth * lobeWidth);
    float darkest = std::min({baseColor.r, baseColor.g, baseColor.b});
    float darkestDiffuse = std::max(darkest, 0.0f) * 0.96f / kPi;
    float dielectricShare = specularPeak / (specularPeak + darkestDiffuse);
    if (environment) {
        float reflected = (0.04f + 0.96f / 21.0f) / kPi;
        dielectricShare = std::max(dielectricShare, reflected / (reflected + darkestDiffuse));
    }
    float specularShare = glm::mix(dielectricShare, 1.0f, std::clamp(metallic, 0.0f, 1.0f));
    float minGain = environment ? SPECULAR_SHARE_MIN_GAIN_ENVIRONMENT : SPECULAR_SHARE_MIN_GAIN;
    float gain =
        std::clamp(SPECULAR_SHARE_TOLERANCE / specularShare, minGain, SPECULAR_SHARE_MAX_GAIN);
    return lobeWidth * gain;
}

// A slot for an instance that has none: a fresh ObjectSlot (no rects) and a zero GPU entry, as
// every instance without a slot has.
uint32_t takeSlot(DecoupledState& d) {
    uint32_t s;
    if (d.freeSlots.empty()) {
        s = uint32_t(d.slots.size());
        d.slots.emplace_back();
        d.slotObjects.emplace_back();
        d.slotObjectsUploaded.emplace_back();
    } else {
        s = d.freeSlots.back();
        d.freeSlots.pop_back();
        d.slots[s] = ObjectSlot{};
        d.slotObjects[s] = gpu::GpuShadelObject{};
    }
    d.slots[s].newThisFrame = true;
    return s;
}

// The visited instances are scattered over per-instance arrays of the whole world (at 1M
// instances: 160 MB of GpuInstance, 12 MB of InstanceEntry, 272 MB of GpuShadelObject), so
// each visit starts with cache and TLB misses (builtin:many 1M: 37% of the coarse allocation's
// samples sat on the first GpuInstance load). Fetching a few visits ahead overlaps them.
// Two stages: an instance's entries first, then (its entry read by then) its slot.
constexpr size_t kPrefetchAhead = 8;

void prefetchLines(const void* p, size_t bytes, int write) {
    const char* c = static_cast<const char*>(p);
    for (size_t o = 0; o < bytes; o += 64)
        write ? __builtin_prefetch(c + o, 1) : __builtin_prefetch(c + o, 0);
}

void prefetchInstance(const DecoupledState& d, const GpuScene& scene, uint32_t i,
                      bool readsInstance) {
    __builtin_prefetch(&d.instances[i]);
    if (!readsInstance) return;
    const auto* inst = reinterpret_cast<const char*>(&scene.instanceInfo[i]);
    __builtin_prefetch(inst);                                        // model
    __builtin_prefetch(inst + offsetof(gpu::GpuInstance, worldMin)); // bounds, mesh, material
    __builtin_prefetch(inst + sizeof(gpu::GpuInstance) - 1);
}

bool holdsSlot(const DecoupledState& d, uint32_t i) {
    return (d.holdsSlot[i >> 6] >> (i & 63)) & 1u;
}

void setHoldsSlot(DecoupledState& d, uint32_t i, bool holds) {
    uint64_t bit = uint64_t(1) << (i & 63);
    d.holdsSlot[i >> 6] = holds ? d.holdsSlot[i >> 6] | bit : d.holdsSlot[i >> 6] & ~bit;
}

void prefetchSlot(const DecoupledState& d, uint32_t i) {
    uint32_t s = d.instances[i].slot;
    if (s == kNoSlot) return;
    prefetchLines(&d.slots[s], kSlotHotBytes, 0);
    prefetchLines(&d.slotObjects[s], sizeof(gpu::GpuShadelObject), 1); // rewritten
}

// The frame's counts start at zero; its shading bias is the base plus the capacity controller's.
void resetFrameCounts(DecoupledState& d) {
    d.shadingBias = d.baseShadingBias + (d.capacityControl ? d.controller.bias : 0.0f);
    d.rects.clear();
    d.rectBlockCount = 0;
    d.wholeLevelBlocks = 0;
    d.windowMoves = 0;
    d.objectsDecoupled = d.objectsForward = d.objectsSmallForward = d.objectsSheetLimited = 0;
    d.objectsRateBiased = 0;
    d.objectsRateTextured = 0;
    d.rateBiasSum = 0.0f;
    d.firstMipHistogram.fill(0);
    d.objectsReusable = 0;
}

// What changed since last frame (reuse_invalidation.h), uploaded for the shading's checks, and
// the lights that keep plain materials at the full rate (material_rate.h).
void prepareChanges(Renderer& r, const GpuScene& scene, const gpu::FrameConstants& constants) {
    Gpu& gpu = *r.gpu;
    DecoupledState& d = *r.decoupled;
    d.changes =
        changedVolumes(r, scene, constants.sunDirection, glm::length(constants.sunColor) > 0.0f);
    d.changesOverflow = d.changes.size() > SHADEL_MAX_CHANGED_VOLUMES;
    if (r.settings.materialRate) { // (read every frame: the viewer switches it)
        const RtSettings& rt = r.settings.rt;
        bool sunSharp = rt.shadows || rt.ao || rt.gi || r.settings.sunCascades > 1;
        static const std::vector<Decal> kNoDecals;
        updateSharpLights(
            d.sharpLights, r.lightsLastFrame.empty() ? scene.lightInfo : r.lightsLastFrame,
            !r.changedLightVolumes.empty(), sunSharp, r.settings.decals ? scene.decals : kNoDecals);
    }
    if (!d.changesOverflow && !d.changes.empty())
        std::memcpy(mapped(gpu, d.changedVolumes), d.changes.data(),
                    d.changes.size() * sizeof(ChangedVolume));
}

// The instances a frame decides (DecoupledState::visit) and where they came from.
struct FrameVisit {
    const std::vector<uint32_t>* seen = nullptr; // --occlusion: the GPU's visible set
    const CoarseVisit* grid = nullptr;           // otherwise: the grid's answer
    size_t viewed = 0;                           // visit entries with their view (the grid's)
    uint32_t frameMark = 0;                      // visitedFrame, seenFrame
};

// Instances near the frustum's bounds, and last frame's (to free or clear what they held):
// every other instance stays unwanted, with its zero entry and no rects.
// With occlusion culling the GPU's visible set of last frame is the set to allocate for
// (the CPU estimator and the GPU agree on what is seen); an instance that appears
// is drawn forward for one frame. Otherwise the grid's answer for the frustum (the visit's
// first half, coarse_visit.h: taken from the frontend worker or computed here), whose
// instances come with their view of the camera already computed.
FrameVisit gatherVisit(Renderer& r, const GpuScene& scene, const CameraView& camera) {
    DecoupledState& d = *r.decoupled;
    FrameVisit visit;
    d.visit.clear();
    visit.seen = visibleLastFrame(r);
    visit.frameMark = uint32_t(d.frameNumber + 1);
    if (visit.seen) {
        d.visitStats.readbackVisits++;
        d.visit.insert(d.visit.end(), visit.seen->begin(), visit.seen->end());
        for (uint32_t i : *visit.seen) d.instances[i].seenFrame = visit.frameMark;
    } else {
        visit.grid = &takeCoarseVisit(r, scene, camera);
        d.visit.insert(d.visit.end(), visit.grid->instances.begin(), visit.grid->instances.end());
    }
    visit.viewed = visit.grid ? visit.grid->views.size() : 0;
    d.visit.insert(d.visit.end(), d.touched.begin(), d.touched.end());
    d.touched.clear();
    return visit;
}

// An object's shading rate (material_rate.h): the GPU adds `bias` to every sample's LOD up to
// the rate's bound (materialRateLod), so the finest level the object can need moves with it.
// A textured material: the bias from the lowest roughness its texture gives, limited per sample
// to `textureLod`, where the view magnifies its textures (texture_rate.h). An edit that changed
// its textures leaves their content unknown: the full rate.
struct ObjectRate {
    float bias = 0.0f;
    float textureLod = SHADEL_TEXTURE_LOD_NONE;
};

ObjectRate objectRate(const Renderer& r, const GpuScene& scene, DecoupledState& d, ObjectSlot& o,
                      const gpu::GpuInstance& inst, const ShadelMeshInfo& mesh,
                      const gpu::GpuMaterial* material, bool known, float roughness,
                      uint32_t features, bool reposed) {
    float rateRoughness = roughness;
    float texLod = SHADEL_TEXTURE_LOD_NONE;
    if ((features & MATERIAL_FEATURE_TEXTURES) != 0u) {
        const MaterialTexels* texels = inst.material < scene.materialTexels.size()
                                           ? &scene.materialTexels[inst.material]
                                           : nullptr;
        bool asLoaded = known && texels && texels->known &&
                        (material == &scene.materialInfo[inst.material] || // not edited
                         sameTextures(*material, scene.materialInfo[inst.material]));
        rateRoughness = asLoaded ? roughness * texels->roughnessScale : 0.0f;
        // Each UV set's textures against that set's mapping: the denser one sets the level.
        texLod = asLoaded ? std::min(textureLod(mesh.uvPerShadelLog2, texels->texelsPerUvLog2,
                                                d.materialRate.shadelsPerTexel),
                                     textureLod(mesh.uv1PerShadelLog2, texels->texelsPerUv1Log2,
                                                d.materialRate.shadelsPerTexel))
                          : -SHADEL_TEXTURE_LOD_NONE;
    }
    float rateBias =
        r.settings.materialRate ? materialRateBias(d.materialRate, features, rateRoughness) : 0.0f;
    if (rateBias > 0.0f) {
        if (o.sharpLightsVersion != d.sharpLights.version || reposed) {
            o.sharpLit = sharpLightReaches(d.sharpLights, inst.worldMin, inst.worldMax);
            o.sharpLightsVersion = d.sharpLights.version;
        }
        if (o.sharpLit) rateBias = 0.0f;
    }
    return {rateBias, texLod};
}

// Preserved layers: a level's shadels may be carried over when last frame marked and
// stored them at the same place (the object was decoupled and the level's rect is
// older than this frame) and nothing the shading reads has changed. Instances and
// materials are static unless animated playback reposes them; lights that moved
// invalidate what they reach.
// View-dependent terms (specular) drift with the camera: the shading pass reshades
// every chunk at least once per refresh period.
// A change that reaches the object (a light that changed, a caster that moved, its
// shadow: reuse_invalidation.h): its chunks check their own shadels against the changed
// regions (shade.comp); an unbounded one (or too many) changes everything.
void markReusableLevels(const Renderer& r, const DecoupledState& d, const ObjectSlot& o,
                        gpu::GpuShadelObject& g, const gpu::GpuInstance& inst,
                        const ShadelMeshInfo& mesh, bool wasDecoupled, bool reposed) {
    ChangeReach reach = d.changesOverflow ? ChangeReach::Everything
                                          : changeReach(d.changes, inst.worldMin, inst.worldMax);
    if (reach == ChangeReach::Bounded) g.flags |= SHADEL_OBJECT_NEAR_CHANGE;
    // Its material changed (texture streaming changed what a texture of it holds, or it
    // was edited): reshade it.
    bool restreamed =
        inst.material < r.changedMaterials.size() && r.changedMaterials[inst.material] != 0;
    bool inputsUnchanged =
        d.reuse && wasDecoupled && reach != ChangeReach::Everything && !restreamed && !reposed;
    for (uint32_t k = o.firstMip; k < mesh.mipCount && inputsUnchanged; ++k)
        if (o.levelSince[k] < d.frameNumber || o.movedAt[k] == d.frameNumber)
            g.reuseLevels |= 1u << k;
}

// The object's levels in its GPU entry (rects, windows, where last frame's shadels are) and in
// the frame's rect list.
void listObjectRects(DecoupledState& d, const ObjectSlot& o, gpu::GpuShadelObject& g,
                     const ShadelMeshInfo& mesh, uint32_t i) {
    g.firstRect = uint32_t(d.rects.size());
    for (uint32_t k = o.firstMip; k < mesh.mipCount; ++k) {
        g.idMapOffset[k] = mesh.idMapOffset[k];
        g.rect[k] = o.rects[k];
        g.window[k] = o.windowOrigin[k].x | (o.windowOrigin[k].y << 16);
        bool moved = o.movedAt[k] == d.frameNumber;
        glm::uvec4 prevRect = moved ? o.movedFromRect[k] : o.rects[k];
        glm::uvec2 prevWindow = moved ? o.movedFromWindow[k] : o.windowOrigin[k];
        g.prevRectOrigin[k] = prevRect.x | (prevRect.y << 16);
        g.prevRectSize[k] = prevRect.z | (prevRect.w << 16);
        g.prevWindow[k] = prevWindow.x | (prevWindow.y << 16);
        d.rects.push_back({o.rects[k], i, k, d.rectBlockCount, 0});
        d.rectBlockCount += o.rects[k].z * o.rects[k].w;
        glm::uvec2 whole = levelBlocks(mesh, k);
        d.wholeLevelBlocks += uint64_t(whole.x) * whole.y;
    }
}

// An instance the view wants decoupled: its rates, sheet rects (or forward when the sheet has
// no room), reuse and GPU entry `g` (zeroed by the caller).
void decideDecoupled(Renderer& r, const GpuScene& scene, uint32_t i, const CoarseInstanceView& view,
                     ObjectSlot& o, gpu::GpuShadelObject& g, bool wasDecoupled) {
    Gpu& gpu = *r.gpu;
    DecoupledState& d = *r.decoupled;
    const gpu::GpuInstance& inst = scene.instanceInfo[i];
    const ShadelMeshInfo& mesh = scene.shadelMeshes[inst.mesh];
    // The material as this frame shades it (edited or as loaded: render/scene_edits).
    bool known = inst.material < scene.materialInfo.size();
    const gpu::GpuMaterial* material = known ? &currentMaterial(r, scene, inst.material) : nullptr;
    float roughness = known ? material->roughnessFactor : 1.0f;
    uint32_t features = known ? materialFeatures(*material) : MATERIAL_FEATURES_ALL;
    // Animated playback posed it anew (moved or deformed): its shadels are shaded again.
    bool reposed = i < r.reposedInstances.size() && r.reposedInstances[i] != 0;
    auto [rateBias, texLod] =
        objectRate(r, scene, d, o, inst, mesh, material, known, roughness, features, reposed);
    uint32_t wantFirst = finestMipFromLod(
        materialRateLod(view.lodBeforeBias + d.shadingBias, rateBias, texLod), 0.0f, mesh.mipCount);
    bool limited = false;
    // No room in the sheet: drawn forward this frame, retried next frame.
    if (!updateObjectRects(gpu, d, o, i, mesh, wantFirst, wasDecoupled, limited)) {
        d.objectsForward++;
        return;
    }
    d.objectsSheetLimited += limited;
    d.objectsDecoupled++;
    o.decoupledLastFrame = true;
    markReusableLevels(r, d, o, g, inst, mesh, wasDecoupled, reposed);
    float metallic = known ? material->metallicFactor : 1.0f;
    glm::vec3 baseColor = known ? glm::vec3(material->baseColorFactor) : glm::vec3(0.0f);
    g.viewDriftCos = std::cos(viewDriftLimitFor(roughness, metallic, baseColor,
                                                r.environment.kind != EnvironmentKind::None));
    g.rateBias = rateBias;
    g.textureLod = rateBias > 0.0f ? texLod : SHADEL_TEXTURE_LOD_NONE;
    d.objectsRateTextured += rateBias > 0.0f && texLod < SHADEL_TEXTURE_LOD_NONE;
    d.objectsRateBiased += rateBias > 0.0f;
    d.rateBiasSum += rateBias;
    d.objectsReusable += g.reuseLevels != 0;
    d.firstMipHistogram[o.firstMip]++;
    g.mip0Size = mesh.mip0Size;
    g.mipCount = mesh.mipCount;
    g.firstMip = o.firstMip;
    g.flags |= SHADEL_OBJECT_DECOUPLED;
    // Its shading class (the pipeline that shades its chunks, shaders/shadel/shade.comp).
    if (features != 0u) g.flags |= SHADEL_OBJECT_FEATURED_MATERIAL;
    if (features == MATERIAL_FEATURE_TEXTURES) g.flags |= SHADEL_OBJECT_TEXTURED_MATERIAL;
    // Or its material program's list (render/materials), if its material names one.
    if (known) g.flags |= materialProgramFlags(d.programs.get(), inst.material);
    // Only point-function procedurals are supersampled (shaders/shadel/prefilter.glsl).
    if ((features & MATERIAL_FEATURE_PROCEDURAL) && r.settings.materialSamples >= 4)
        g.flags |= SHADEL_OBJECT_SUPERSAMPLED; // 2 x 2 samples at least
    listObjectRects(d, o, g, mesh, i);
}

// Decides every visited instance once: forward (holding nothing, or giving its rects back) or
// decoupled (decideDecoupled), into its slot's copy of its GPU entry.
void decideObjects(Renderer& r, const GpuScene& scene, const CameraView& camera,
                   const gpu::FrameConstants& constants, const FrameVisit& visit) {
    Gpu& gpu = *r.gpu;
    DecoupledState& d = *r.decoupled;
    auto planes = frustumPlanes(constants.viewProj);
    const std::vector<uint32_t>* seen = visit.seen;
    const CoarseVisit* grid = visit.grid;
    const size_t viewed = visit.viewed;
    const uint32_t frameMark = visit.frameMark;
    // In the grid's answer, whether the view wants the instance decoupled.
    auto viewWants = [&](size_t v) { return grid->views[v].inFrustum && !grid->views[v].small; };
    for (size_t v = 0; v < d.visit.size(); ++v) {
        if (v + kPrefetchAhead < d.visit.size()) {
            size_t ahead = v + kPrefetchAhead;
            // Past the grid's answer (or with occlusion) the loop reads the instance itself;
            // in it, only where the view wants it decoupled (and its entry where it holds a slot).
            bool readsInstance = ahead >= viewed || viewWants(ahead);
            if (readsInstance || holdsSlot(d, d.visit[ahead]))
                prefetchInstance(d, scene, d.visit[ahead], readsInstance);
        }
        if (v + kPrefetchAhead / 2 < d.visit.size())
            prefetchSlot(d, d.visit[v + kPrefetchAhead / 2]);
        uint32_t i = d.visit[v];
        // Forward this frame and holding nothing, as before: nothing to decide or undo (the grid
        // lists an instance once, and d.touched only instances that hold a slot).
        if (v < viewed && !viewWants(v) && !holdsSlot(d, i)) {
            if (grid->views[v].inFrustum) d.objectsSmallForward++, d.objectsForward++;
            continue;
        }
        InstanceEntry& entry = d.instances[i];
        if (entry.visitedFrame == frameMark) continue;
        entry.visitedFrame = frameMark;
        // Hidden by occlusion last frame: its rects go back (it returns forward for a frame).
        bool hidden = seen && entry.seenFrame != frameMark;
        CoarseInstanceView view;
        if (v < viewed)
            view = grid->views[v];
        else if (!hidden)
            view = viewInstance(d.visitPolicy, scene, camera, planes, i);
        // (The visibility buffer sees only the nearest surface: with it, transparent surfaces
        // are marked by the raster pass below.)
        bool wanted = !hidden && view.inFrustum;
        bool small = wanted && view.small;
        if (small) d.objectsSmallForward++, d.objectsForward++;
        // Drawn forward: without a slot it holds nothing and its GPU entry is zero already (the
        // common case of the many small instances the GPU sees every frame: no slot churn).
        if ((!wanted || small) && entry.slot == kNoSlot) continue;
        if (entry.slot == kNoSlot) {
            entry.slot = takeSlot(d);
            setHoldsSlot(d, i, true);
        }
        ObjectSlot& o = d.slots[entry.slot];
        bool wasDecoupled = o.decoupledLastFrame;
        o.decoupledLastFrame = false;
        gpu::GpuShadelObject& g = d.slotObjects[entry.slot];
        g = gpu::GpuShadelObject{};
        if (!wanted || small) {
            if (o.allocated) freeObject(gpu, d, o);
            continue;
        }
        decideDecoupled(r, scene, i, view, o, g, wasDecoupled);
    }
}

// The GPU entries of the visited instances that changed (an unchanged entry is not written
// again), the slots of instances left holding nothing back to the pool, and the frame's rects.
void uploadObjectEntries(Gpu& gpu, DecoupledState& d, uint32_t frameMark) {
    auto* objects = static_cast<gpu::GpuShadelObject*>(mapped(gpu, d.objectBuffer));
    // Whether the slot's instance entry must be written: a new slot's entry is zero, another's
    // holds what was uploaded last.
    auto entryChanged = [&d](uint32_t s) {
        return d.slots[s].newThisFrame || std::memcmp(&d.slotObjectsUploaded[s], &d.slotObjects[s],
                                                      sizeof(gpu::GpuShadelObject)) != 0;
    };
    for (size_t v = 0; v < d.visit.size(); ++v) {
        // Two stages ahead: the slot's uploaded copy, then (compared by then) the GPU entry of
        // an instance that writes it. An instance without a slot writes nothing.
        if (v + 2 * kPrefetchAhead < d.visit.size()) {
            uint32_t j = d.visit[v + 2 * kPrefetchAhead];
            uint32_t s = holdsSlot(d, j) ? d.instances[j].slot : kNoSlot;
            if (s != kNoSlot)
                prefetchLines(&d.slotObjectsUploaded[s], sizeof(gpu::GpuShadelObject), 0);
        }
        if (v + kPrefetchAhead < d.visit.size()) {
            uint32_t j = d.visit[v + kPrefetchAhead];
            uint32_t s = holdsSlot(d, j) ? d.instances[j].slot : kNoSlot;
            if (s != kNoSlot && entryChanged(s))
                prefetchLines(&objects[j], sizeof(gpu::GpuShadelObject), 1);
        }
        uint32_t i = d.visit[v];
        // Holding no slot: forward, its entry zero (a visitedFrame left set by the loop above
        // is this frame's number, which no later frame matches).
        if (!holdsSlot(d, i)) continue;
        InstanceEntry& entry = d.instances[i];
        if (entry.visitedFrame != frameMark) continue;
        entry.visitedFrame = 0;              // once per instance (visit may list it twice)
        if (entry.slot == kNoSlot) continue; // forward, holding nothing: its entry stays zero
        ObjectSlot& o = d.slots[entry.slot];
        const gpu::GpuShadelObject& g = d.slotObjects[entry.slot];
        bool touched = g.flags != 0 || o.allocated;
        if (touched || !o.newThisFrame) { // else its entry is zero already
            if (entryChanged(entry.slot)) {
                objects[i] = g;
                d.slotObjectsUploaded[entry.slot] = g;
            }
        }
        o.newThisFrame = false;
        if (touched) {
            d.touched.push_back(i);
        } else { // nothing held: the slot goes back to the pool
            d.freeSlots.push_back(entry.slot);
            entry.slot = kNoSlot;
            setHoldsSlot(d, i, false);
        }
    }
    std::memcpy(mapped(gpu, d.rectBuffer), d.rects.data(),
                d.rects.size() * sizeof(gpu::GpuShadelRect));
}

// The frame's gpu::ShadelFrame: every buffer's address at this frame's parity, the counts and
// tunables the passes read.
void writeShadelFrame(Renderer& r, const GpuScene& scene, gpu::FrameConstants& constants) {
    Gpu& gpu = *r.gpu;
    DecoupledState& d = *r.decoupled;
    gpu::ShadelFrame s{};
    s.objects = address(gpu, d.objectBuffer);
    uint32_t now = d.parity(), prev = now ^ 1u;
    s.occupancy = address(gpu, d.occupancy[now]);
    s.offsetMap = address(gpu, d.offsetMap[now]);
    s.prevOccupancy = address(gpu, d.occupancy[prev]);
    s.prevOffsetMap = address(gpu, d.offsetMap[prev]);
    s.chunkViews = address(gpu, d.chunkViews[now]);
    s.prevChunkViews = address(gpu, d.chunkViews[prev]);
    bool showReuse = r.settings.visualize == Visualize::Reuse;
    if (showReuse && !d.chunkReasons)
        d.chunkReasons =
            need(createBuffer(gpu, {"shadel.chunkReasons", VkDeviceSize(d.capacityChunks) * 4, 0,
                                    MemoryKind::DeviceLocal}),
                 "shadel.chunkReasons");
    s.chunkReasons = showReuse ? address(gpu, d.chunkReasons) : 0u;
    s.allocId = address(gpu, d.allocId);
    s.counters = address(gpu, d.counters);
    s.rects = address(gpu, d.rectBuffer);
    s.markedBlocks = address(gpu, d.markedBlocks);
    s.queue = address(gpu, d.queue);
    s.copyQueue = address(gpu, d.copyQueue);
    s.classQueues = address(gpu, d.classQueues);
    s.idMaps = address(gpu, scene.idMaps);
    s.shadelUvs = address(gpu, scene.shadelUvs);
    s.sheetBlocks = d.sheetBlocks;
    s.rectCount = uint32_t(d.rects.size());
    s.rectBlockCount = d.rectBlockCount;
    for (uint32_t l = 0; l < SHADEL_LAYERS; ++l) {
        s.layers[l] = address(gpu, d.storage.frames[now][l]);
        s.prevLayers[l] = address(gpu, d.storage.frames[prev][l]);
    }
    s.changedVolumes = address(gpu, d.changedVolumes);
    s.levelWants = address(gpu, d.levelWants);
    s.changedVolumeCount = d.changesOverflow ? 0u : uint32_t(d.changes.size());
    s.frameNumber = uint32_t(d.frameNumber);
    s.reuse = d.reuse ? 1u : 0u;
    s.refreshPeriod = d.refreshPeriod;
    s.capacityChunks = d.capacityChunks;
    s.markedCapacity = d.capacityChunks;
    s.allocationCounters = std::clamp(r.settings.allocationCounters, 1u, SHADEL_COUNTERS);
    s.shadingBias = d.shadingBias;
    s.trilinearBand = d.trilinearBand;
    s.materialSamples = r.settings.materialSamples;
    for (uint32_t k = 0; k < SHADEL_MAX_MIPS; ++k) s.regionStart[k] = d.regions[k].x0;
    std::memcpy(mapped(gpu, d.frameInfo), &s, sizeof(s));
    constants.shadel = address(gpu, d.frameInfo);
    constants.shadingBias = d.shadingBias;
}

} // namespace

void prepareDecoupledFrame(Renderer& r, const GpuScene& scene, const CameraView& camera,
                           gpu::FrameConstants& constants) {
    resetFrameCounts(*r.decoupled);
    prepareChanges(r, scene, constants);
    FrameVisit visit = gatherVisit(r, scene, camera);
    decideObjects(r, scene, camera, constants, visit);
    uploadObjectEntries(*r.gpu, *r.decoupled, visit.frameMark);
    writeShadelFrame(r, scene, constants);
}

bool drawnDecoupled(const Renderer& r, uint32_t instance) {
    const DecoupledState* d = r.decoupled.get();
    if (!d || instance >= d->instances.size()) return false;
    uint32_t slot = d->instances[instance].slot;
    return slot != kNoSlot && (d->slotObjects[slot].flags & SHADEL_OBJECT_DECOUPLED) != 0u;
}

} // namespace shadel
