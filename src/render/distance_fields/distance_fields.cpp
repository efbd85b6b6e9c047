#include "render/distance_fields/distance_fields.h"

#include <chrono>
#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_inverse.hpp>

#include "bake/mesh_distance_field.h"
#include "core/error.h"
#include "core/log.h"
#include "distance_fields/df_types.h"
#include "render/distance_fields/df_atlas.h"
#include "render/renderer.h"

namespace shadel {

// Atlas volume in voxels: 8 MiB of floats, room for ~100 fields of 24 voxels along their
// longest side.
constexpr Extent<3> kAtlasSize{128, 128, 128};

// A field not wanted for this many frames leaves the atlas (its room is reused); one wanted again
// within them is still there.
constexpr uint64_t kResidencyKeepFrames = 8;

struct DistanceFieldState {
    DistanceFieldAtlas atlas{kAtlasSize};
    BufferHandle atlasBuffer, meshes, instances, frame, readback;
    // Residency (--df-residency): every field stays on the CPU; the atlas holds those of meshes
    // with an instance within the distance of the camera. The atlas's CPU copy is uploaded
    // whole on a frame whose residency changed (8 MiB; rare).
    float residencyDistance = 0.0f;                     // 0: every field placed at load, for good
    std::vector<MeshDistanceField> fields;              // per mesh; empty: casts none
    std::vector<gpu::GpuDistanceFieldMesh> meshInfo;    // what `meshes` holds
    std::vector<gpu::GpuDistanceFieldInstance> casters; // what `instances` holds
    std::vector<uint32_t> casterInstance;               // their scene instances
    std::vector<uint32_t> relit;      // scene instances whose field came or went this frame
    std::vector<uint64_t> lastWanted; // per mesh: frame it was last wanted
    std::vector<float> volume;        // what `atlasBuffer` holds
    uint64_t frameNumber = 0;
    uint64_t streamedIn = 0, evicted = 0, noRoom = 0; // over the run
    TextureHandle output; // RGBA8: DF sun visibility, shadow-map visibility, DF AO, covered
    TextureWriteView outputWrite;
    uint32_t meshesWithField = 0, meshesPlaced = 0, instancesCasting = 0, cacheHits = 0;
    double buildSeconds = 0;
    double shadowVsMapDb = 0;
    uint64_t overlapPixels = 0;
    double meanAo = 1;
};

void DistanceFieldStateDeleter::operator()(DistanceFieldState* s) const {
    delete s;
}

// Places mesh m's field in the atlas and its CPU copy; false when the atlas has no room (the
// mesh then casts no distance-field shadow until room frees up).
static bool placeField(DistanceFieldState& s, uint32_t m) {
    const MeshDistanceField& f = s.fields[m];
    auto place = s.atlas.add(m, {f.resolution.x, f.resolution.y, f.resolution.z});
    if (!place) return false;
    ++s.meshesPlaced;
    for (uint32_t z = 0; z < f.resolution.z; ++z)
        for (uint32_t y = 0; y < f.resolution.y; ++y) {
            size_t row = (size_t(place->origin[2] + z) * kAtlasSize[1] + place->origin[1] + y) *
                             kAtlasSize[0] +
                         place->origin[0];
            std::memcpy(&s.volume[row],
                        &f.distances[(size_t(z) * f.resolution.y + y) * f.resolution.x],
                        f.resolution.x * sizeof(float));
        }
    gpu::GpuDistanceFieldMesh& g = s.meshInfo[m];
    g.atlasOrigin = {place->origin[0], place->origin[1], place->origin[2]};
    g.valid = 1;
    g.resolution = f.resolution;
    g.voxelSize = f.voxelSize;
    g.origin = f.origin;
    return true;
}

static void evictField(DistanceFieldState& s, uint32_t m) {
    s.atlas.remove(m);
    s.meshInfo[m].valid = 0;
    --s.meshesPlaced;
}

void updateDistanceFieldResidency(Renderer& r, DistanceFieldState& s, glm::vec3 camera) {
    ++s.frameNumber;
    s.relit.clear();
    if (s.residencyDistance == 0.0f) return;
    std::vector<uint8_t> wasResident(s.fields.size());
    for (uint32_t m = 0; m < s.fields.size(); ++m) wasResident[m] = uint8_t(s.meshInfo[m].valid);
    for (const gpu::GpuDistanceFieldInstance& c : s.casters) {
        glm::vec3 nearest = glm::clamp(camera, c.worldMin, c.worldMax);
        if (glm::length(nearest - camera) <= s.residencyDistance)
            s.lastWanted[c.mesh] = s.frameNumber;
    }
    bool changed = false;
    // Out first, so the room they free can take the fields coming in.
    for (uint32_t m = 0; m < s.fields.size(); ++m)
        if (s.meshInfo[m].valid && s.frameNumber - s.lastWanted[m] > kResidencyKeepFrames) {
            evictField(s, m);
            ++s.evicted;
            changed = true;
        }
    for (uint32_t m = 0; m < s.fields.size(); ++m) {
        if (s.meshInfo[m].valid || s.lastWanted[m] != s.frameNumber) continue;
        if (!placeField(s, m)) {
            ++s.noRoom;
            continue;
        }
        ++s.streamedIn;
        changed = true;
    }
    if (!changed) return;
    // What casts a distance-field shadow changed: shading that carried those shadows (decoupled
    // reuse) is stale where they fall (render/shadel/reuse_invalidation.h).
    for (size_t c = 0; c < s.casters.size(); ++c)
        if (wasResident[s.casters[c].mesh] != uint8_t(s.meshInfo[s.casters[c].mesh].valid))
            s.relit.push_back(s.casterInstance[c]);
    // Between frames: the GPU is idle.
    uploadBuffer(*r.gpu, s.atlasBuffer, s.volume.data(), s.volume.size() * sizeof(float));
    uploadBuffer(*r.gpu, s.meshes, s.meshInfo.data(), s.meshInfo.size() * sizeof(s.meshInfo[0]));
}

DistanceFieldStatePtr createDistanceFields(Renderer& r, const Scene& scene,
                                           const GpuScene& gpuScene, const std::string& cacheDir) {
    Gpu& gpu = *r.gpu;
    auto s = DistanceFieldStatePtr(new DistanceFieldState);
    auto start = std::chrono::steady_clock::now();
    // Meshes that cast: those of opaque (or alpha-tested) instances.
    std::vector<bool> casts(scene.meshes.size(), false);
    for (const gpu::GpuInstance& inst : gpuScene.instanceInfo)
        if (inst.mesh < casts.size() &&
            !(gpuScene.materialInfo[inst.material].flags & MATERIAL_ALPHA_BLEND))
            casts[inst.mesh] = true;
    s->residencyDistance = r.settings.dfResidencyDistance;
    s->volume.assign(size_t(kAtlasSize[0]) * kAtlasSize[1] * kAtlasSize[2], 1e3f);
    s->meshInfo.assign(std::max<size_t>(scene.meshes.size(), 1), {});
    s->fields.resize(scene.meshes.size());
    s->lastWanted.assign(scene.meshes.size(), 0);
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        if (!casts[m]) continue;
        bool cached = false;
        MeshDistanceField f = loadOrBuildMeshDistanceField(scene.meshes[m], cacheDir, &cached);
        if (f.distances.empty()) continue;
        s->cacheHits += cached;
        ++s->meshesWithField;
        s->fields[m] = std::move(f);
        // With a residency distance the first frame places what it wants.
        if (s->residencyDistance == 0.0f) placeField(*s, uint32_t(m));
    }
    std::vector<gpu::GpuDistanceFieldInstance>& instances = s->casters;
    for (const gpu::GpuInstance& inst : gpuScene.instanceInfo) {
        if (inst.mesh >= s->fields.size() || s->fields[inst.mesh].distances.empty()) continue;
        gpu::GpuDistanceFieldInstance d{};
        d.worldToObject = glm::inverse(inst.model);
        d.scale = glm::length(glm::vec3(inst.model[0]));
        d.worldMin = inst.worldMin;
        d.worldMax = inst.worldMax;
        d.mesh = inst.mesh;
        instances.push_back(d);
        s->casterInstance.push_back(uint32_t(&inst - gpuScene.instanceInfo.data()));
    }
    s->instancesCasting = uint32_t(instances.size());
    if (instances.empty()) instances.push_back({});
    s->buildSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    auto buffer = [&](const char* name, const void* data, size_t bytes) {
        BufferHandle b = createBuffer(gpu, {name, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT});
        if (!b) throw DeviceError(format("out of GPU memory for %s", name));
        uploadBuffer(gpu, b, data, bytes);
        return b;
    };
    s->atlasBuffer = buffer("df.atlas", s->volume.data(), s->volume.size() * sizeof(float));
    s->meshes =
        buffer("df.meshes", s->meshInfo.data(), s->meshInfo.size() * sizeof(s->meshInfo[0]));
    s->instances =
        buffer("df.instances", instances.data(), instances.size() * sizeof(instances[0]));
    gpu::DistanceFieldFrame frame{};
    frame.atlas = address(gpu, s->atlasBuffer);
    frame.meshes = address(gpu, s->meshes);
    frame.instances = address(gpu, s->instances);
    frame.instanceCount = s->instancesCasting;
    frame.atlasSize = {kAtlasSize[0], kAtlasSize[1], kAtlasSize[2]};
    frame.softness = 24.0f; // penumbrae about as wide as the shadow map's 3x3 PCF
    s->frame = buffer("df.frame", &frame, sizeof(frame));

    TextureDesc out;
    out.name = "df.lighting";
    out.format = VK_FORMAT_R8G8B8A8_UNORM;
    out.width = r.internalWidth;
    out.height = r.internalHeight;
    out.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    s->output = createTexture(gpu, out);
    s->readback = createBuffer(gpu, {"df.lighting.readback",
                                     VkDeviceSize(r.internalWidth) * r.internalHeight * 4,
                                     VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryKind::Readback});
    if (!s->output || !s->readback) throw DeviceError("out of GPU memory for df.lighting");
    s->outputWrite = createWriteView(gpu, s->output);
    DistanceFieldState* state = s.get();
    registerTextureCapture(
        r.captures, gpu, "df.lighting",
        "distance fields: R DF sun visibility, G shadow-map visibility, B DF AO (PNG)",
        CaptureKind::Display, [state] { return state->output; }, VK_IMAGE_LAYOUT_GENERAL);
    SHADEL_INFO("distance fields: %u meshes (%u from the cache), %u in the atlas, %u instances, "
                "%.2f s",
                s->meshesWithField, s->cacheHits, s->meshesPlaced, s->instancesCasting,
                s->buildSeconds);
    return s;
}

void destroyDistanceFields(Renderer& r, DistanceFieldState& s) {
    Gpu& gpu = *r.gpu;
    destroy(gpu, s.outputWrite);
    destroy(gpu, s.output);
    for (BufferHandle b : {s.atlasBuffer, s.meshes, s.instances, s.frame, s.readback})
        if (b) destroy(gpu, b);
}

const std::vector<uint32_t>& distanceFieldRelitInstances(const DistanceFieldState& s) {
    return s.relit;
}

uint64_t distanceFieldFrameAddress(const Renderer& r, const DistanceFieldState& s) {
    return address(*r.gpu, s.frame);
}

uint32_t distanceFieldOutputSlot(const Renderer& r, const DistanceFieldState& s) {
    return slot(*r.gpu, s.outputWrite).value;
}

void beginDistanceFieldOutput(Renderer& r, DistanceFieldState& s, VkCommandBuffer cmd) {
    // Cleared: pixels of tiles the pass skips (sky) read as not covered.
    VkImage image = vkImage(*r.gpu, s.output);
    imageBarrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                 VK_IMAGE_LAYOUT_GENERAL,
                 VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_COPY_BIT, 0,
                 VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    VkClearColorValue zero{};
    VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdClearColorImage(cmd, image, VK_IMAGE_LAYOUT_GENERAL, &zero, 1, &range);
    imageBarrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
                 VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_CLEAR_BIT,
                 VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                 VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
}

void recordDistanceFieldReadback(Renderer& r, DistanceFieldState& s, VkCommandBuffer cmd) {
    Gpu& gpu = *r.gpu;
    VkImage image = vkImage(gpu, s.output);
    imageBarrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
                 VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                 VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                 VK_ACCESS_2_TRANSFER_READ_BIT);
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {r.internalWidth, r.internalHeight, 1};
    vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_GENERAL, vkBuffer(gpu, s.readback), 1,
                           &copy);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
}

void finishDistanceFieldFrame(Renderer& r, DistanceFieldState& s) {
    const uint8_t* px = static_cast<const uint8_t*>(mapped(*r.gpu, s.readback));
    size_t n = size_t(r.internalWidth) * r.internalHeight;
    double se = 0, ao = 0;
    uint64_t count = 0, surfaces = 0;
    for (size_t i = 0; i < n; ++i) {
        if (px[4 * i + 3] < 128) continue; // not a surface
        ao += px[4 * i + 2] / 255.0;
        ++surfaces;
        if (px[4 * i + 3] != 255) continue; // faces away from the sun: both shadows are 0
        double d = double(px[4 * i]) - double(px[4 * i + 1]);
        se += d * d;
        ++count;
    }
    s.overlapPixels = count;
    double mse = count ? se / double(count) : 0.0;
    s.shadowVsMapDb = mse == 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
    s.meanAo = surfaces ? ao / double(surfaces) : 1.0;
}

void distanceFieldStats(const DistanceFieldState& s, nlohmann::json& stats) {
    stats["distance_fields"] = {{"meshes", s.meshesWithField},
                                {"meshes_in_atlas", s.meshesPlaced},
                                {"residency_distance", s.residencyDistance},
                                {"streamed_in", s.streamedIn},
                                {"evicted", s.evicted},
                                {"no_room", s.noRoom},
                                {"atlas_valid", s.atlas.validate()},
                                {"from_cache", s.cacheHits},
                                {"instances", s.instancesCasting},
                                {"atlas_voxels_used", s.atlas.usedVoxels()},
                                {"build_seconds", s.buildSeconds},
                                {"shadow_vs_shadow_map_db", s.shadowVsMapDb},
                                {"overlap_pixels", s.overlapPixels},
                                {"mean_ao", s.meanAo}};
}

} // namespace shadel
