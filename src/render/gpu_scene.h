#pragma once
// The scene on the GPU (unified geometry): one vertex buffer and one index buffer
// for every mesh, material and instance tables, textures in the bindless table.
#include <array>
#include <vector>

#include "common/shared_types.h"
#include "render/shadel/texture_rate.h"
#include "rhi/gpu.h"
#include "scene/scene.h"

namespace shadel {

struct BakedMesh;

// A mesh's shadel space as the decoupled path sees it.
struct ShadelMeshInfo {
    glm::uvec2 mip0Size{0};
    uint32_t mipCount = 0;    // 0: no shadel space (drawn forward)
    float shadelsPerUnit = 0; // MIP-0 shadels per object-space unit (BakedMesh::shadelsPerMetre)
    // log2 of the material-UV units a MIP-0 shadel spans (render/shadel/texture_rate.h), in
    // the first UV set and in the second
    float uvPerShadelLog2 = 0;
    float uv1PerShadelLog2 = 0;
    std::array<uint32_t, SHADEL_MAX_MIPS> idMapOffset{}; // 16-bit units into GpuScene::idMaps
    uint64_t idMapTexels = 0;
};

struct GpuScene {
    BufferHandle vertices;  // gpu::GpuVertex[]
    BufferHandle shadelUvs; // vec2 per vertex (decoupled path), invalid when not baked
    BufferHandle indices;   // uint32
    // The visibility prepass's index buffer (the scene's, each triangle turned to start at a
    // visibility vertex of its own) and its vertices (uvec2: scene vertex, triangle):
    // scene/visibility_vertices.h.
    BufferHandle visibilityIndices;
    BufferHandle visibilityVertices;
    BufferHandle meshes;    // gpu::GpuMesh[]
    BufferHandle meshLods;  // gpu::GpuMeshLods[] per mesh (render/culling/mesh_lods.h)
    BufferHandle instances; // gpu::GpuInstance[]
    BufferHandle materials; // gpu::GpuMaterial[]
    BufferHandle lights;    // gpu::GpuLight[] (every kind but the sun: the first directional light)
    BufferHandle blockers;  // gpu::GpuLightBlocker[]
    BufferHandle portals;   // gpu::GpuLightPortal[]
    BufferHandle lightBlockerLists; // uint blocker indices (GpuLight::blockerFirst/Count)
    uint32_t blockerCount = 0;
    std::vector<TextureHandle> textures;
    std::vector<TextureReadView> textureViews;
    std::vector<gpu::GpuMesh> meshInfo;
    std::vector<gpu::GpuMeshLods> lodInfo; // what `meshLods` holds
    // Per vertex of `vertices`: the index into its Scene mesh's vertices it was made from (baked
    // seams and fetch order reorder them); animated playback rewrites vertices through it.
    std::vector<uint32_t> vertexSource;
    std::vector<ShadelMeshInfo> shadelMeshes; // per mesh, when baked
    BufferHandle idMaps;                      // every mesh's triangle-ID maps, all MIPs
    std::vector<gpu::GpuInstance> instanceInfo;
    std::vector<gpu::GpuLight> lightInfo;       // what `lights` holds
    std::vector<uint8_t> lightCastsShadow;      // per lightInfo entry (GI light views)
    std::vector<gpu::GpuMaterial> materialInfo; // what `materials` holds
    // Per material: its program (Material::shadelMaterial), empty = the built-in glTF PBR one.
    std::vector<std::string> materialPrograms;
    // Per material as loaded: its textures' density and roughness bound (the texture-limited
    // shading rate: render/shadel/texture_rate.h).
    std::vector<MaterialTexels> materialTexels;
    std::vector<ParticleEmitter> emitters; // the scene's, simulated by render/particles
    std::vector<Decal> decals;             // the scene's, culled and applied by render/decals
    uint32_t instanceCount = 0;
    uint32_t lightCount = 0;
    Aabb bounds;
    // The sun: the first directional light of the scene (none: sunColor = 0).
    glm::vec3 sunDirection{0.3f, -1.0f, 0.2f};
    glm::vec3 sunColor{0.0f};
    bool sunCastsShadow = false;
    glm::vec3 skyColor{0.5f};
    glm::vec3 ambientColor{0.05f};
    Scene::Environment environment = Scene::Environment::Sky; // Scene::environment
    uint64_t geometryBytes = 0;
    uint64_t idMapBytes = 0;
};

// Uploads the scene. With `baked` (one per mesh), each mesh's vertices are the baked ones
// (duplicated along chart seams) so forward and decoupled paths draw identical geometry.
// With `streamedTextureSlots` (one bindless slot per scene texture, render/streaming), textures
// are not uploaded: materials use those slots, whose contents the streaming system manages.
void uploadScene(Gpu& gpu, const Scene& scene, GpuScene& out,
                 const std::vector<BakedMesh>* baked = nullptr,
                 const std::vector<uint32_t>* streamedTextureSlots = nullptr);
// One scene light as the GPU sees it; appends the blockers it lists to `blockerLists`.
// `textureSlot`: the bindless slot of the light's texture (gobo, area emission), or NO_TEXTURE.
gpu::GpuLight gpuLight(const Light& light, std::vector<uint32_t>& blockerLists,
                       uint32_t textureSlot = NO_TEXTURE);
void destroyScene(Gpu& gpu, GpuScene& scene);

// Whether any material is alpha-masked (glTF alphaMode MASK).
bool hasAlphaMaskedMaterials(const GpuScene& scene);

// The MATERIAL_FEATURE_* the material uses: what shaders/common/material.glsl must evaluate for
// it (a shader compiled without them, kMaterialFeatures, shades it the same).
uint32_t materialFeatures(const gpu::GpuMaterial& m);
// The material's bindless texture slots in TextureSlot order (scene.h), NO_TEXTURE when absent.
std::array<uint32_t, kTextureSlotCount> materialTextureSlots(const gpu::GpuMaterial& m);
// Writes materialFeatures into the material's flags (MATERIAL_FEATURES_SHIFT): the forward draw
// lists and the tile pass read them. Uploaded and edited materials carry them.
void setMaterialFeatureFlags(gpu::GpuMaterial& m);

} // namespace shadel
