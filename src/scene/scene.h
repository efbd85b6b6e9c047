#pragma once
// The scene model: plain data, no GPU objects. Importers (glTF, built-in scenes) fill it;
// the baker and the renderers read it.
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "common/shared_types.h"
#include "scene/decal.h"
#include "scene/particle_emitter.h"

namespace shadel {

struct Aabb {
    glm::vec3 min{1e30f};
    glm::vec3 max{-1e30f};
    void extend(glm::vec3 p) { min = glm::min(min, p), max = glm::max(max, p); }
    void extend(const Aabb& b) { min = glm::min(min, b.min), max = glm::max(max, b.max); }
    bool valid() const { return min.x <= max.x && min.y <= max.y && min.z <= max.z; }
    glm::vec3 center() const { return (min + max) * 0.5f; }
    glm::vec3 extent() const { return max - min; }
};
Aabb transformAabb(const Aabb& box, const glm::mat4& m);

// The one vertex format of the unified geometry buffer (few vertex formats).
struct Vertex {
    glm::vec3 position;
    glm::vec3 normal;
    glm::vec4 tangent; // xyz tangent, w handedness
    glm::vec2 uv0;     // material UVs, glTF TEXCOORD_0 (may overlap / tile: never shadel space)
    glm::vec2 uv1;     // the second set, TEXCOORD_1 (uv0 where the mesh has none)
};

// What GPU skinning (render/skinning) needs of a skinned mesh, parallel to Mesh::vertices: the
// vertices before skinning (morph targets applied) and four joints and weights each; joints
// index Scene::skinPoses[skin].joints.
struct MeshSkin {
    uint32_t skin = 0;
    std::vector<Vertex> bindVertices;
    std::vector<glm::uvec4> joints;
    std::vector<glm::vec4> weights;
};

// A skinned node's joint matrices at the scene's time: world(joint) x inverseBind (glTF).
struct SkinPose {
    std::vector<glm::mat4> joints;
};

// One glTF primitive = one mesh here: one material, triangles only.
struct Mesh {
    std::string name;
    std::vector<Vertex> vertices;
    std::vector<uint32_t> indices; // triangle list
    uint32_t material = 0;
    Aabb bounds;
    // Skinned meshes: vertices hold the CPU-skinned pose; `skin` lets the GPU skin them instead.
    std::shared_ptr<const MeshSkin> skin;
    uint32_t triangleCount() const { return uint32_t(indices.size() / 3); }
};

// A glTF points or lines primitive of one node (drawn forward only, in both modes:
// render/points_lines). Lines are a list of segments (strips and loops unrolled).
struct PointLineSet {
    std::string name;
    bool lines = false;            // false: one point per vertex; true: vertex pairs
    std::vector<Vertex> vertices;  // object space
    std::vector<glm::vec4> colors; // COLOR_0 per vertex, or empty (white)
    uint32_t material = 0;
    glm::mat4 transform{1.0f}; // object to world
};

enum class AlphaMode : uint32_t { Opaque = 0, Mask = 1, Blend = 2 };

// Procedural patterns evaluated in the material code (shared by forward and decoupled paths).
enum class Procedural : uint32_t {
    None = 0,
    TexelChecker = 1, // one-texel checker on uv0 * proceduralScale: aliases under forward shading
    Bricks = 2,       // low-frequency coloured bricks
};

constexpr int32_t kNoTexture = -1;

// What screen-space passes treat a surface as (material classes, written to the thin
// G-buffer, render/screenspace): skin gets subsurface scattering, water the water composite.
// Unlit materials are SurfaceClass::Unlit whatever this says.
enum class SurfaceClass : uint32_t { DefaultLit = 0, Foliage = 1, Skin = 2, Water = 3, Unlit = 4 };

// The material's texture slots, in the order of Material::uvTransforms and the GPU's.
enum class TextureSlot : uint32_t {
    BaseColor = 0,
    MetallicRoughness,
    Normal,
    Emissive,
    Occlusion,
    Clearcoat,          // KHR_materials_clearcoat: R = coat weight
    ClearcoatRoughness, // G = coat roughness
    ClearcoatNormal,
    Specular,       // KHR_materials_specular: A = specular strength
    SpecularColor,  // RGB = dielectric F0 tint
    SheenColor,     // KHR_materials_sheen: RGB = sheen colour
    SheenRoughness, // A = sheen roughness
    Transmission,   // KHR_materials_transmission: R = transmission
    Thickness,      // KHR_materials_volume: G = thickness
    Count
};
constexpr uint32_t kTextureSlotCount = uint32_t(TextureSlot::Count);

// KHR_texture_transform: uv' = c0 * u + c1 * v + c2 (identity when absent).
struct UvTransform {
    glm::vec2 c0{1.0f, 0.0f}, c1{0.0f, 1.0f}, c2{0.0f, 0.0f};
};

// A glTF sampler (SAMPLER_WRAP_*, SAMPLER_MAG_*, SAMPLER_MIN_* of common/shared_types.h); the
// defaults are glTF's for a texture without one: repeat, linear, trilinear.
struct TextureSampler {
    uint8_t wrapS = SAMPLER_WRAP_REPEAT, wrapT = SAMPLER_WRAP_REPEAT;
    uint8_t mag = SAMPLER_MAG_LINEAR, min = SAMPLER_MIN_LINEAR_MIPMAP_LINEAR;
    bool operator==(const TextureSampler&) const = default;
};
// Its index in the bindless sampler table (rhi/bindless.h).
inline uint32_t samplerIndex(const TextureSampler& s) {
    return SAMPLER_MATERIAL_FIRST +
           ((uint32_t(s.wrapS) * 3u + s.wrapT) * 2u + s.mag) * SAMPLER_MIN_COUNT + s.min;
}

struct Material {
    std::string name;
    glm::vec4 baseColorFactor{1.0f};
    glm::vec3 emissiveFactor{0.0f};
    float metallicFactor = 0.0f;
    float roughnessFactor = 0.8f;
    float normalScale = 1.0f;
    float occlusionStrength = 1.0f;
    float alphaCutoff = 0.5f;
    AlphaMode alphaMode = AlphaMode::Opaque;
    bool doubleSided = false;
    int32_t baseColorTexture = kNoTexture; // index into Scene::textures
    int32_t metallicRoughnessTexture = kNoTexture;
    int32_t normalTexture = kNoTexture;
    int32_t emissiveTexture = kNoTexture;
    int32_t occlusionTexture = kNoTexture;
    Procedural procedural = Procedural::None;
    float proceduralScale = 1.0f; // pattern cells per uv unit
    // Blended materials only: 0 = alpha-blended, 1 = additive (the additiveness channel),
    // composited without sorting by weighted blended OIT (render/oit).
    float additiveness = 0.0f;
    // The material program that shades it decoupled (render/materials): a .shmat path or
    // "builtin:NAME"; empty = the built-in glTF PBR program. glTF: extras.shadel_material.
    std::string shadelMaterial;

    // glTF material extensions (scene/gltf_materials.h); the defaults leave core PBR unchanged.
    UvTransform uvTransforms[kTextureSlotCount];
    TextureSampler samplers[kTextureSlotCount]; // per TextureSlot: its texture's glTF sampler
    // Per TextureSlot: the UV set it reads, 0 (Vertex::uv0) or 1 (uv1): the texture info's
    // texCoord, or KHR_texture_transform's when it gives one.
    uint8_t texCoords[kTextureSlotCount] = {};
    bool unlit = false; // KHR_materials_unlit: the base colour is the output
    float clearcoatFactor = 0.0f;
    float clearcoatRoughnessFactor = 0.0f;
    float clearcoatNormalScale = 1.0f;
    int32_t clearcoatTexture = kNoTexture;
    int32_t clearcoatRoughnessTexture = kNoTexture;
    int32_t clearcoatNormalTexture = kNoTexture;
    float ior = 1.5f;                    // KHR_materials_ior: dielectric F0 = ((ior-1)/(ior+1))^2
    float specularFactor = 1.0f;         // KHR_materials_specular: scales dielectric F0 and F90
    glm::vec3 specularColorFactor{1.0f}; // tints dielectric F0
    glm::vec3 sheenColorFactor{0.0f};    // KHR_materials_sheen (0: no sheen)
    float sheenRoughnessFactor = 0.0f;
    int32_t specularTexture = kNoTexture; // the factors' textures (TextureSlot::Specular...)
    int32_t specularColorTexture = kNoTexture;
    int32_t sheenColorTexture = kNoTexture;
    int32_t sheenRoughnessTexture = kNoTexture;
    SurfaceClass surfaceClass = SurfaceClass::DefaultLit;
    // KHR_materials_transmission: the share of the diffuse lobe that is instead specular
    // transmission through the surface (render/transmission); KHR_materials_volume: the
    // thickness (mesh space) the refracted ray travels, and Beer-Lambert attenuation in it.
    float transmissionFactor = 0.0f;
    int32_t transmissionTexture = kNoTexture;
    float thicknessFactor = 0.0f; // 0: thin-walled
    int32_t thicknessTexture = kNoTexture;
    glm::vec3 attenuationColor{1.0f};
    float attenuationDistance = std::numeric_limits<float>::infinity();
};

// A texture made by code instead of stored pixels (scene/procedural_textures.h): its texels
// are generated when the streaming file is built (bake/texture_pack.h), never kept in the scene.
struct ProceduralTexture {
    uint32_t kind = 0; // 0 = none: the texture has pixels
    uint32_t seed = 0;
};

struct Texture {
    std::string name;
    uint32_t width = 0, height = 0;
    std::vector<uint8_t> rgba8; // width*height*4, top row first (empty when procedural)
    bool srgb = false;          // base colour and emissive are sRGB, the rest linear
    ProceduralTexture procedural;
};

struct Instance {
    std::string name;
    uint32_t mesh = 0;
    glm::mat4 transform{1.0f}; // object to world
    bool character = false;    // outlined, and tinted where hidden (--stencil-effects)
};

// Point is the omni light; Spot has a round cone, SquareSpot a square one (a pyramid whose
// half-angles are the cone angles, turned about the direction by `axis`); Tube is a line light
// of `tubeLength` along `axis` (a capsule's closest-point lighting); Area is a one-sided
// rectangle of `areaSize` (along `axis`, and along cross(direction, axis)) centred at `position`,
// emitting `texture` (or a flat colour) toward `direction`. A spot with a `texture` projects it
// (a gobo). glTF KHR_lights_punctual gives Directional, Point and Spot.
enum class LightType : uint32_t {
    Directional = 0,
    Point = 1,
    Spot = 2,
    SquareSpot = 3,
    Tube = 4,
    Area = 5
};

struct Light {
    std::string name;
    LightType type = LightType::Point;
    glm::vec3 color{1.0f};
    float intensity = 1.0f;        // lux for directional, candela for point/spot (glTF units)
    glm::vec3 position{0.0f};      // world
    glm::vec3 direction{0, -1, 0}; // world, the way the light travels
    float range = 0.0f;            // 0 = infinite
    float innerConeAngle = 0.0f;
    float outerConeAngle = 0.7853982f;
    bool castsShadow = false;
    bool softShadow = false; // shadow-casting spots: variable penumbra (PCSS) instead of PCF
    float lightSize = 0.1f;  // the emitter's width (metres): PCSS penumbra size
    bool dark = false;       // a negative light: subtracts what it would add
    glm::vec3 axis{1, 0, 0}; // tube: the segment; square spot, gobo, area: the "right" axis
    float tubeLength = 0.0f; // tube: the segment's length
    float tubeRadius = 0.0f; // tube: its radius (softens the highlight)
    // Spots: a gobo (projected texture); area lights: the emitted texture (radiance = colour *
    // intensity * texel). Index into Scene::textures, kNoTexture for none.
    int32_t texture = kNoTexture;
    float textureTiling = 1.0f;     // gobo: repeats of the texture across the outer cone
    glm::vec2 areaSize{1.0f, 1.0f}; // area: width (along axis), height (metres)
    bool hasClipPlane = false;      // lights only where dot(clipPlane, (p, 1)) >= 0
    glm::vec4 clipPlane{0, 1, 0, 0};
    std::vector<uint32_t> blockers; // indices into Scene::blockers that stop this light
};

// A light blocker: an artist-placed rectangle (say a wall's mid-plane) that stops
// the lights listing it, without shadow maps. Portals are rectangular holes in it (doorways).
struct LightBlocker {
    std::string name;
    glm::vec3 center{0.0f};
    glm::vec3 axisU{1, 0, 0}; // unit, in the plane
    glm::vec3 axisV{0, 1, 0}; // unit, in the plane, orthogonal to axisU
    glm::vec2 halfSize{1.0f}; // along axisU, axisV
    struct Portal {
        glm::vec2 min, max; // in metres along axisU, axisV from the centre
    };
    std::vector<Portal> portals;
};

// A fixed light propagation volume an artist places: GI is computed once
// in a grid over this box and read before the camera-centred cascades where it holds a point
// (render/gi). glTF: a node whose extras have "shadel_gi_volume": true; the box is the node's
// unit cube ([-1, 1]^3, as an empty's cube display) in world space.
struct GiVolume {
    std::string name;
    Aabb box;
};

struct Camera {
    std::string name;
    glm::vec3 position{0.0f};
    glm::vec3 forward{0, 0, -1};
    glm::vec3 up{0, 1, 0};
    float yfov = 0.8f; // radians
    float znear = 0.05f;
    float zfar = 500.0f;
    // > 0: orthographic, half the view's height in world units (glTF ymag); yfov is unused.
    float orthoHalfHeight = 0.0f;
    // Made by the engine, not the file: refitted to the scene for the run's aspect and field of
    // view (render/camera_framing.h).
    bool automatic = false;
};

struct Scene {
    std::string name;
    std::vector<Mesh> meshes;
    std::vector<Material> materials;
    std::vector<Texture> textures;
    std::vector<Instance> instances;
    std::vector<Light> lights;
    std::vector<LightBlocker> blockers;
    std::vector<Camera> cameras;           // the first is the default
    std::vector<ParticleEmitter> emitters; // GPU particles (render/particles)
    std::vector<SkinPose> skinPoses;       // per skinned node (MeshSkin::skin)
    std::vector<PointLineSet> pointLines;  // glTF points and lines primitives
    std::vector<Decal> decals;             // projected box decals (render/decals)
    std::vector<GiVolume> giVolumes;       // local GI volumes (render/gi)
    glm::vec3 skyColor{0.55f, 0.7f, 0.95f};
    glm::vec3 ambientColor{0.08f, 0.09f, 0.11f};
    // What lights the scene when --environment does not say: the physically based sky of its
    // sun, or its sky and ambient colours as a hemisphere (rooms and night scenes authored so).
    enum class Environment { Sky, Hemisphere };
    Environment environment = Environment::Sky;

    Aabb worldBounds() const;
    uint64_t triangleCount() const; // over instances
};

} // namespace shadel
