#include "render/gpu_scene.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "bake/bake.h"
#include "core/log.h"
#include "render/culling/mesh_lods.h"
#include "render/normal_matrix.h"
#include "scene/visibility_vertices.h"

namespace shadel {

static BufferHandle uploadArray(Gpu& gpu, const char* name, const void* data, size_t bytes,
                                VkBufferUsageFlags usage = 0) {
    size_t size = std::max<size_t>(bytes, 16);
    BufferHandle b = createBuffer(gpu, {name, size, usage, MemoryKind::DeviceLocal});
    if (!b) throw DeviceError(format("out of GPU memory uploading %s (%zu bytes)", name, bytes));
    if (bytes) uploadBuffer(gpu, b, data, bytes);
    return b;
}

static uint32_t mipCount(uint32_t w, uint32_t h) {
    return 1 + uint32_t(std::floor(std::log2(double(std::max(w, h)))));
}

gpu::GpuLight gpuLight(const Light& l, std::vector<uint32_t>& blockerLists, uint32_t textureSlot) {
    gpu::GpuLight g{};
    bool spot = l.type == LightType::Spot || l.type == LightType::SquareSpot;
    bool gobo = spot && textureSlot != NO_TEXTURE;
    g.position = l.position;
    g.type = uint32_t(l.type);
    g.direction = glm::normalize(l.direction);
    g.range = l.range;
    g.color = l.color * l.intensity * (l.dark ? -1.0f : 1.0f);
    g.flags = (l.dark ? LIGHT_FLAG_DARK : 0u) | (l.hasClipPlane ? LIGHT_FLAG_CLIP_PLANE : 0u) |
              (l.softShadow ? LIGHT_FLAG_SOFT_SHADOW : 0u) | (gobo ? LIGHT_FLAG_PROJECTED : 0u);
    g.shadowIndex = LIGHT_NO_SHADOW; // given by uploadScene to shadow-casting spots
    g.clipPlane = l.clipPlane;
    if (l.type == LightType::SquareSpot) {
        // On the tangent of the angle off the axis, per side of the square.
        float tanOuter = std::tan(std::min(l.outerConeAngle, 1.5f));
        float tanInner = std::tan(std::min(l.innerConeAngle, 1.5f));
        g.spotScale = 1.0f / std::max(tanOuter - tanInner, 1e-4f);
        g.spotOffset = tanOuter * g.spotScale;
    } else {
        float cosOuter = std::cos(l.outerConeAngle), cosInner = std::cos(l.innerConeAngle);
        g.spotScale = 1.0f / std::max(cosInner - cosOuter, 1e-4f);
        g.spotOffset = -cosOuter * g.spotScale;
    }
    // The square cone's (gobo's, rectangle's) right axis and the tube's segment: orthogonal to
    // the direction for spots and area lights.
    glm::vec3 axis = glm::length(l.axis) > 0.0f ? glm::normalize(l.axis) : glm::vec3(1, 0, 0);
    if (l.type == LightType::SquareSpot || gobo || l.type == LightType::Area) {
        axis -= g.direction * glm::dot(axis, g.direction);
        if (glm::length(axis) < 1e-4f)
            axis = glm::cross(g.direction, std::abs(g.direction.y) < 0.9f ? glm::vec3(0, 1, 0)
                                                                          : glm::vec3(1, 0, 0));
        axis = glm::normalize(axis);
    }
    g.axis = axis;
    g.halfLength = l.type == LightType::Tube ? 0.5f * l.tubeLength : 0.0f;
    // Tubes: the tube's radius; spots: the emitter's width (soft shadows' penumbra).
    g.radius = l.type == LightType::Tube ? l.tubeRadius : l.lightSize;
    g.textureSlot = gobo || l.type == LightType::Area ? textureSlot : NO_TEXTURE;
    g.textureScale = 1.0f;
    if (gobo) {
        // UV = 0.5 + tan(angle off the axis) * textureScale along right and up: the outer cone
        // spans the texture `textureTiling` times.
        float tanOuter = std::tan(std::clamp(l.outerConeAngle, 1e-3f, 1.5f));
        g.textureScale = 0.5f * std::max(l.textureTiling, 1e-3f) / tanOuter;
    }
    if (l.type == LightType::Area) {
        g.halfLength = 0.5f * std::max(l.areaSize.x, 1e-3f);
        g.radius = 0.5f * std::max(l.areaSize.y, 1e-3f);
    }
    g.blockerFirst = uint32_t(blockerLists.size());
    g.blockerCount = uint32_t(std::min<size_t>(l.blockers.size(), LIGHT_MAX_BLOCKERS_PER_LIGHT));
    blockerLists.insert(blockerLists.end(), l.blockers.begin(),
                        l.blockers.begin() + g.blockerCount);
    return g;
}

// The glTF material extensions' part of a GPU material (scene.h Material).
template <typename SlotOf>
static void setMaterialExtensions(gpu::GpuMaterial& g, const Material& m, SlotOf&& textureSlot) {
    for (uint32_t t = 0; t < kTextureSlotCount; ++t) {
        g.uvTransform[t * 3 + 0] = m.uvTransforms[t].c0;
        g.uvTransform[t * 3 + 1] = m.uvTransforms[t].c1;
        g.uvTransform[t * 3 + 2] = m.uvTransforms[t].c2;
    }
    for (uint32_t& word : g.samplers) word = 0;
    for (uint32_t t = 0; t < kTextureSlotCount; ++t)
        g.samplers[t / 4] |= samplerIndex(m.samplers[t]) << (8 * (t % 4));
    g.texCoords = 0;
    for (uint32_t t = 0; t < kTextureSlotCount; ++t)
        if (m.texCoords[t] == 1) g.texCoords |= 1u << t;
    g.clearcoatTexture = textureSlot(m.clearcoatTexture);
    g.clearcoatRoughnessTexture = textureSlot(m.clearcoatRoughnessTexture);
    g.clearcoatNormalTexture = textureSlot(m.clearcoatNormalTexture);
    g.clearcoatFactor = m.clearcoatFactor;
    g.clearcoatRoughnessFactor = m.clearcoatRoughnessFactor;
    g.clearcoatNormalScale = m.clearcoatNormalScale;
    float r = (m.ior - 1.0f) / (m.ior + 1.0f);
    g.dielectricF0Scalar = r * r * m.specularFactor;
    g.specularColorFactor = m.specularColorFactor;
    g.specularFactor = m.specularFactor;
    g.sheenColorFactor = m.sheenColorFactor;
    g.sheenRoughnessFactor = m.sheenRoughnessFactor;
    g.specularTexture = textureSlot(m.specularTexture);
    g.specularColorTexture = textureSlot(m.specularColorTexture);
    g.sheenColorTexture = textureSlot(m.sheenColorTexture);
    g.sheenRoughnessTexture = textureSlot(m.sheenRoughnessTexture);
    g.transmissionFactor = m.transmissionFactor;
    g.transmissionTexture = textureSlot(m.transmissionTexture);
    g.thicknessFactor = m.thicknessFactor;
    g.thicknessTexture = textureSlot(m.thicknessTexture);
    g.attenuationColor = m.attenuationColor;
    g.attenuationDistance = m.attenuationDistance;
    g.ior = m.ior;
}
static_assert(kTextureSlotCount == TEXTURE_SLOT_COUNT && 3 * TEXTURE_SLOT_COUNT == 42 &&
                  TEXTURE_SLOT_COUNT <= 4 * 4,
              "scene.h TextureSlot and shared_types.h TEXTURE_SLOT_* agree");

namespace {

using TextureSlotOf = std::function<uint32_t(int32_t)>;

// Every texture with a full mip chain and a bindless slot, sRGB for colour data. Streamed
// textures (render/streaming) keep their slots there; none load here.
void uploadTextures(Gpu& gpu, const Scene& scene, GpuScene& out,
                    const std::vector<uint32_t>* streamedTextureSlots) {
    std::vector<bool> srgb(scene.textures.size(), false);
    for (const Material& m : scene.materials) {
        if (m.baseColorTexture >= 0 && size_t(m.baseColorTexture) < srgb.size())
            srgb[m.baseColorTexture] = true;
        if (m.emissiveTexture >= 0 && size_t(m.emissiveTexture) < srgb.size())
            srgb[m.emissiveTexture] = true;
    }
    for (const Light& l : scene.lights) // gobos and area lights' emission are colour
        if (l.texture >= 0 && size_t(l.texture) < srgb.size()) srgb[l.texture] = true;
    for (size_t i = 0; !streamedTextureSlots && i < scene.textures.size(); ++i) {
        const Texture& t = scene.textures[i];
        if (t.rgba8.empty()) { // procedural: its texels exist only in the streaming file
            SHADEL_WARN("texture %zu (%s) has no texels here (it streams): drawn untextured", i,
                        t.name.c_str());
            out.textures.push_back({});
            out.textureViews.push_back({});
            continue;
        }
        TextureDesc d;
        d.name = format("texture.%s", t.name.empty() ? std::to_string(i).c_str() : t.name.c_str());
        d.format = (srgb[i] || t.srgb) ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_R8G8B8A8_UNORM;
        d.width = t.width;
        d.height = t.height;
        d.mipLevels = mipCount(t.width, t.height);
        d.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
        TextureHandle tex = createTexture(gpu, d);
        if (!tex) {
            SHADEL_WARN("texture %s does not fit in GPU memory: drawn untextured", d.name.c_str());
            out.textures.push_back({});
            out.textureViews.push_back({});
            continue;
        }
        uploadTexture(gpu, tex, t.rgba8.data(), t.rgba8.size());
        out.textures.push_back(tex);
        out.textureViews.push_back(createReadView(gpu, tex));
    }
}

// The GPU materials (a default one when the scene has none), their texture slots resolved.
std::vector<gpu::GpuMaterial> buildMaterials(const Scene& scene, const TextureSlotOf& textureSlot) {
    std::vector<gpu::GpuMaterial> materials;
    for (const Material& m : scene.materials) {
        gpu::GpuMaterial g{};
        g.baseColorFactor = m.baseColorFactor;
        g.emissiveFactor = m.emissiveFactor;
        g.metallicFactor = m.metallicFactor;
        g.roughnessFactor = m.roughnessFactor;
        g.normalScale = m.normalScale;
        g.occlusionStrength = m.occlusionStrength;
        g.alphaCutoff = m.alphaCutoff;
        g.baseColorTexture = textureSlot(m.baseColorTexture);
        g.metallicRoughnessTexture = textureSlot(m.metallicRoughnessTexture);
        g.normalTexture = textureSlot(m.normalTexture);
        g.emissiveTexture = textureSlot(m.emissiveTexture);
        g.occlusionTexture = textureSlot(m.occlusionTexture);
        g.flags = (m.alphaMode == AlphaMode::Mask ? MATERIAL_ALPHA_MASK : 0u) |
                  (m.alphaMode == AlphaMode::Blend ? MATERIAL_ALPHA_BLEND : 0u) |
                  (m.doubleSided ? MATERIAL_DOUBLE_SIDED : 0u) | (m.unlit ? MATERIAL_UNLIT : 0u);
        // Blended and unlit materials keep their own paths (transmission is a lit, opaque lobe).
        if (m.transmissionFactor > 0.0f && m.alphaMode != AlphaMode::Blend && !m.unlit)
            g.flags |= MATERIAL_TRANSMISSION;
        g.flags |= (uint32_t(m.surfaceClass) & MATERIAL_CLASS_MASK) << MATERIAL_CLASS_SHIFT;
        g.procedural = uint32_t(m.procedural);
        g.proceduralScale = m.proceduralScale;
        g.additiveness =
            m.alphaMode == AlphaMode::Blend ? std::clamp(m.additiveness, 0.0f, 1.0f) : 0.0f;
        setMaterialExtensions(g, m, textureSlot);
        materials.push_back(g);
    }
    if (materials.empty()) {
        gpu::GpuMaterial g{};
        g.baseColorFactor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
        g.roughnessFactor = 0.7f;
        g.baseColorTexture = g.metallicRoughnessTexture = g.normalTexture = g.emissiveTexture =
            g.occlusionTexture = NO_TEXTURE;
        setMaterialExtensions(g, Material{}, [](int32_t) { return NO_TEXTURE; });
        materials.push_back(g);
    }
    for (gpu::GpuMaterial& g : materials) setMaterialFeatureFlags(g);
    return materials;
}

// Every mesh with its LODs into the unified vertex, shadel-UV and index arrays; baked meshes in
// their baked vertex order, so the triangle-ID maps index their triangles.
void appendSceneGeometry(const Scene& scene, const std::vector<BakedMesh>* baked, GpuScene& out,
                         std::vector<gpu::GpuVertex>& vertices, std::vector<glm::vec2>& shadelUvs,
                         std::vector<uint32_t>& indices) {
    out.meshInfo.clear();
    out.lodInfo.clear();
    out.vertexSource.clear();
    for (size_t mi = 0; mi < scene.meshes.size(); ++mi) {
        const Mesh& mesh = scene.meshes[mi];
        gpu::GpuMesh g{};
        g.vertexOffset = int32_t(vertices.size());
        g.shadelMesh = 0xFFFFFFFFu;
        g.boundsMin = mesh.bounds.min;
        g.boundsMax = mesh.bounds.max;
        const BakedMesh* b = baked ? &(*baked)[mi] : nullptr;
        MeshGeometry geometry;
        if (b && !b->indices.empty()) {
            for (size_t v = 0; v < b->vertexRemap.size(); ++v) {
                const Vertex& src = mesh.vertices[b->vertexRemap[v]];
                geometry.vertices.push_back(
                    {src.position, src.normal, src.tangent, src.uv0, src.uv1});
            }
            geometry.shadelUvs = b->shadelUv;
            geometry.sources = b->vertexRemap;
            geometry.indices = b->indices;
            geometry.keepTriangleOrder = true; // the triangle-ID maps index LOD 0's triangles
            g.shadelMesh = uint32_t(mi);
        } else {
            for (const Vertex& v : mesh.vertices)
                geometry.vertices.push_back({v.position, v.normal, v.tangent, v.uv0, v.uv1});
            geometry.indices = mesh.indices;
        }
        // LOD 0 and its simplified levels, all in the unified buffers (render/culling).
        gpu::GpuMeshLods lods =
            appendMeshWithLods(std::move(geometry), vertices, baked ? &shadelUvs : nullptr, indices,
                               &out.vertexSource);
        g.firstIndex = lods.lod[0].firstIndex;
        g.indexCount = lods.lod[0].indexCount;
        out.meshInfo.push_back(g);
        out.lodInfo.push_back(lods);
    }
}

std::vector<gpu::GpuInstance> buildInstances(const Scene& scene, size_t materialCount,
                                             GpuScene& out) {
    std::vector<gpu::GpuInstance> instances;
    out.bounds = Aabb{};
    for (const Instance& inst : scene.instances) {
        gpu::GpuInstance g{};
        g.model = inst.transform;
        g.normalMatrix = normalMatrixOf(inst.transform);
        Aabb world = transformAabb(scene.meshes[inst.mesh].bounds, inst.transform);
        g.worldMin = world.min;
        g.worldMax = world.max;
        g.mesh = inst.mesh;
        uint32_t material = scene.meshes[inst.mesh].material;
        g.material = material < materialCount ? material : 0;
        instances.push_back(g);
        out.bounds.extend(world);
    }

    out.instanceInfo = instances;
    return instances;
}

// Triangle-ID maps of every baked mesh and MIP, packed as 16-bit values.
void uploadIdMaps(Gpu& gpu, const Scene& scene, const std::vector<BakedMesh>& baked,
                  GpuScene& out) {
    std::vector<uint16_t> idMaps;
    {
        out.shadelMeshes.resize(scene.meshes.size());
        for (size_t mi = 0; mi < scene.meshes.size(); ++mi) {
            const BakedMesh& b = baked[mi];
            ShadelMeshInfo& info = out.shadelMeshes[mi];
            if (b.indices.empty() || b.idMaps.empty()) continue;
            info.mip0Size = {b.width, b.height};
            info.shadelsPerUnit = b.shadelsPerMetre;
            std::vector<glm::vec2> materialUv(b.vertexRemap.size());
            for (size_t v = 0; v < b.vertexRemap.size(); ++v)
                materialUv[v] = scene.meshes[mi].vertices[b.vertexRemap[v]].uv0;
            info.uvPerShadelLog2 =
                uvPerShadelLog2(materialUv, b.shadelUv, b.indices, info.mip0Size);
            for (size_t v = 0; v < b.vertexRemap.size(); ++v)
                materialUv[v] = scene.meshes[mi].vertices[b.vertexRemap[v]].uv1;
            info.uv1PerShadelLog2 =
                uvPerShadelLog2(materialUv, b.shadelUv, b.indices, info.mip0Size);
            info.mipCount = std::min<uint32_t>(b.mipCount(), SHADEL_MAX_MIPS);
            for (uint32_t k = 0; k < info.mipCount; ++k) {
                info.idMapOffset[k] = uint32_t(idMaps.size());
                idMaps.insert(idMaps.end(), b.idMaps[k].begin(), b.idMaps[k].end());
                info.idMapTexels += b.idMaps[k].size();
            }
            if (idMaps.size() % 2) idMaps.push_back(0xFFFF);
            if (idMaps.size() > 0xFFFFFFFFull)
                throw DeviceError("triangle-ID maps exceed 4 G texels: lower --density");
        }
        out.idMaps = uploadArray(gpu, "scene.idMaps", idMaps.data(), idMaps.size() * 2);
        out.idMapBytes = idMaps.size() * 2;
    }
}

// The lights after the sun (which goes to out.sun*), their blocker lists and spot shadow
// indices; the blockers and their portals.
struct SceneLights {
    std::vector<gpu::GpuLight> lights;
    std::vector<uint32_t> lightBlockers;
    std::vector<gpu::GpuLightBlocker> blockers;
    std::vector<gpu::GpuLightPortal> portals;
};
SceneLights buildLights(const Scene& scene, GpuScene& out, const TextureSlotOf& textureSlot) {
    SceneLights sl;
    std::vector<gpu::GpuLight>& lights = sl.lights;
    std::vector<uint32_t>& lightBlockers = sl.lightBlockers;
    std::vector<gpu::GpuLightBlocker>& blockers = sl.blockers;
    std::vector<gpu::GpuLightPortal>& portals = sl.portals;
    bool haveSun = false;
    uint32_t spotShadows = 0;
    for (const Light& l : scene.lights) {
        if (l.type == LightType::Directional && !haveSun) {
            haveSun = true;
            out.sunDirection = glm::normalize(l.direction);
            out.sunColor = l.color * l.intensity;
            out.sunCastsShadow = true;
            continue;
        }
        lights.push_back(gpuLight(l, lightBlockers, textureSlot(l.texture)));
        // Spot shadow maps (render/lighting/spot_shadows.h), in light order, up to the atlas's.
        bool spot = l.type == LightType::Spot || l.type == LightType::SquareSpot;
        if (l.castsShadow && spot && spotShadows < LIGHT_MAX_SPOT_SHADOWS)
            lights.back().shadowIndex = spotShadows++;
        out.lightCastsShadow.push_back(l.castsShadow ? 1 : 0);
    }
    for (const LightBlocker& b : scene.blockers) {
        gpu::GpuLightBlocker g{};
        g.center = b.center;
        g.axisU = glm::normalize(b.axisU);
        g.axisV = glm::normalize(b.axisV);
        g.halfU = b.halfSize.x;
        g.halfV = b.halfSize.y;
        g.normal = glm::normalize(glm::cross(g.axisU, g.axisV));
        g.firstPortal = uint32_t(portals.size());
        g.portalCount = uint32_t(b.portals.size());
        for (const LightBlocker::Portal& p : b.portals) portals.push_back({p.min, p.max});
        blockers.push_back(g);
    }
    return sl;
}

} // namespace

void uploadScene(Gpu& gpu, const Scene& scene, GpuScene& out, const std::vector<BakedMesh>* baked,
                 const std::vector<uint32_t>* streamedTextureSlots) {
    uploadTextures(gpu, scene, out, streamedTextureSlots);
    auto textureSlot = [&](int32_t index) -> uint32_t {
        if (streamedTextureSlots)
            return index >= 0 && size_t(index) < streamedTextureSlots->size()
                       ? (*streamedTextureSlots)[index]
                       : NO_TEXTURE;
        if (index < 0 || size_t(index) >= out.textureViews.size() || !out.textureViews[index])
            return NO_TEXTURE;
        return slot(gpu, out.textureViews[index]).value;
    };

    std::vector<gpu::GpuMaterial> materials = buildMaterials(scene, textureSlot);
    out.materialTexels = materialTexels(scene);
    out.materialTexels.resize(materials.size()); // (the default material: no textures)
    std::vector<gpu::GpuVertex> vertices;
    std::vector<glm::vec2> shadelUvs;
    std::vector<uint32_t> indices;
    appendSceneGeometry(scene, baked, out, vertices, shadelUvs, indices);
    std::vector<gpu::GpuInstance> instances = buildInstances(scene, materials.size(), out);
    if (baked) uploadIdMaps(gpu, scene, *baked, out);
    SceneLights sl = buildLights(scene, out, textureSlot);
    const std::vector<gpu::GpuLight>& lights = sl.lights;
    const std::vector<uint32_t>& lightBlockers = sl.lightBlockers;
    const std::vector<gpu::GpuLightBlocker>& blockers = sl.blockers;
    const std::vector<gpu::GpuLightPortal>& portals = sl.portals;
    out.skyColor = scene.skyColor;
    out.emitters = scene.emitters;
    out.decals = scene.decals;
    out.ambientColor = scene.ambientColor;
    out.environment = scene.environment;

    VkBufferUsageFlags indexUsage = VK_BUFFER_USAGE_INDEX_BUFFER_BIT;
    // Ray tracing (render/raytracing) builds BLASes straight from the unified geometry.
    VkBufferUsageFlags rtInput =
        gpu.device.optional.rayQuery
            ? VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR
            : 0;
    out.vertices = uploadArray(gpu, "scene.vertices", vertices.data(),
                               vertices.size() * sizeof(gpu::GpuVertex), rtInput);
    if (baked)
        out.shadelUvs = uploadArray(gpu, "scene.shadelUvs", shadelUvs.data(),
                                    shadelUvs.size() * sizeof(glm::vec2));
    out.indices =
        uploadArray(gpu, "scene.indices", indices.data(), indices.size() * 4, indexUsage | rtInput);
    size_t visibilityBytes = 0;
    {
        std::vector<MeshIndexRange> ranges;
        for (size_t mi = 0; mi < out.meshInfo.size(); ++mi) {
            uint32_t first = out.meshInfo[mi].firstIndex;
            uint32_t next = mi + 1 < out.meshInfo.size() ? out.meshInfo[mi + 1].firstIndex
                                                         : uint32_t(indices.size());
            ranges.push_back({first, next - first, out.meshInfo[mi].vertexOffset});
        }
        VisibilityGeometry vis = buildVisibilityGeometry(indices, ranges);
        visibilityBytes = vis.indices.size() * 4 + vis.vertices.size() * sizeof(glm::uvec2);
        out.visibilityIndices = uploadArray(gpu, "scene.visibilityIndices", vis.indices.data(),
                                            vis.indices.size() * 4, indexUsage);
        out.visibilityVertices = uploadArray(gpu, "scene.visibilityVertices", vis.vertices.data(),
                                             vis.vertices.size() * sizeof(glm::uvec2));
    }
    out.meshes = uploadArray(gpu, "scene.meshes", out.meshInfo.data(),
                             out.meshInfo.size() * sizeof(gpu::GpuMesh));
    out.meshLods = uploadArray(gpu, "scene.meshLods", out.lodInfo.data(),
                               out.lodInfo.size() * sizeof(gpu::GpuMeshLods));
    out.instances = uploadArray(gpu, "scene.instances", instances.data(),
                                instances.size() * sizeof(gpu::GpuInstance));
    out.materialInfo = materials;
    for (const Material& m : scene.materials) out.materialPrograms.push_back(m.shadelMaterial);
    out.materials = uploadArray(gpu, "scene.materials", materials.data(),
                                materials.size() * sizeof(gpu::GpuMaterial));
    out.lights =
        uploadArray(gpu, "scene.lights", lights.data(), lights.size() * sizeof(gpu::GpuLight));
    out.blockers = uploadArray(gpu, "scene.lightBlockers", blockers.data(),
                               blockers.size() * sizeof(gpu::GpuLightBlocker));
    out.portals = uploadArray(gpu, "scene.lightPortals", portals.data(),
                              portals.size() * sizeof(gpu::GpuLightPortal));
    out.lightBlockerLists =
        uploadArray(gpu, "scene.lightBlockerLists", lightBlockers.data(), lightBlockers.size() * 4);
    out.blockerCount = uint32_t(blockers.size());
    out.instanceCount = uint32_t(instances.size());
    out.lightCount = uint32_t(lights.size());
    out.lightInfo = lights;
    out.geometryBytes =
        vertices.size() * sizeof(gpu::GpuVertex) + indices.size() * 4 + visibilityBytes;
}

void destroyScene(Gpu& gpu, GpuScene& s) {
    for (TextureReadView v : s.textureViews) destroy(gpu, v);
    for (TextureHandle t : s.textures) destroy(gpu, t);
    for (BufferHandle b : {s.vertices, s.shadelUvs, s.indices, s.visibilityIndices,
                           s.visibilityVertices, s.meshes, s.meshLods, s.instances, s.materials,
                           s.lights, s.idMaps, s.blockers, s.portals, s.lightBlockerLists})
        destroy(gpu, b);
    s = GpuScene{};
}

void setMaterialFeatureFlags(gpu::GpuMaterial& m) {
    m.flags = (m.flags & ~MATERIAL_FEATURED) | (materialFeatures(m) << MATERIAL_FEATURES_SHIFT);
}

std::array<uint32_t, kTextureSlotCount> materialTextureSlots(const gpu::GpuMaterial& m) {
    static_assert(kTextureSlotCount == 14, "one entry per TextureSlot, in its order");
    return {m.baseColorTexture,          m.metallicRoughnessTexture, m.normalTexture,
            m.emissiveTexture,           m.occlusionTexture,         m.clearcoatTexture,
            m.clearcoatRoughnessTexture, m.clearcoatNormalTexture,   m.specularTexture,
            m.specularColorTexture,      m.sheenColorTexture,        m.sheenRoughnessTexture,
            m.transmissionTexture,       m.thicknessTexture};
}

uint32_t materialFeatures(const gpu::GpuMaterial& m) {
    uint32_t features = 0u;
    for (uint32_t texture : materialTextureSlots(m))
        if (texture != NO_TEXTURE) features |= MATERIAL_FEATURE_TEXTURES;
    if (m.procedural == PROCEDURAL_TEXEL_CHECKER || m.procedural == PROCEDURAL_BRICKS)
        features |= MATERIAL_FEATURE_PROCEDURAL;
    if (m.clearcoatFactor > 0.0f) features |= MATERIAL_FEATURE_CLEARCOAT;
    if (glm::any(glm::greaterThan(m.sheenColorFactor, glm::vec3(0.0f))))
        features |= MATERIAL_FEATURE_SHEEN;
    return features;
}

bool hasAlphaMaskedMaterials(const GpuScene& scene) {
    for (const gpu::GpuMaterial& m : scene.materialInfo)
        if (m.flags & MATERIAL_ALPHA_MASK) return true;
    return false;
}

} // namespace shadel
