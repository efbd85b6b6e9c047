#pragma once
// The scene model: plain data, no GPU objects. Importers (glTF, built-in scenes) fill it;
// the baker and the renderers read it.
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

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

// The one vertex format of the unified geometry buffer (seed 003: few vertex formats).
struct Vertex {
    glm::vec3 position;
    glm::vec3 normal;
    glm::vec4 tangent; // xyz tangent, w handedness
    glm::vec2 uv0;     // material UVs (may overlap / tile: never used for shadel space)
};

// One glTF primitive = one mesh here: one material, triangles only.
struct Mesh {
    std::string name;
    std::vector<Vertex> vertices;
    std::vector<uint32_t> indices; // triangle list
    uint32_t material = 0;
    Aabb bounds;
    uint32_t triangleCount() const { return uint32_t(indices.size() / 3); }
};

enum class AlphaMode : uint32_t { Opaque = 0, Mask = 1, Blend = 2 };

// Procedural patterns evaluated in the material code (shared by forward and decoupled paths).
enum class Procedural : uint32_t {
    None = 0,
    TexelChecker = 1, // one-texel checker on uv0 * proceduralScale: aliases under forward shading
    Bricks = 2,       // low-frequency coloured bricks
};

constexpr int32_t kNoTexture = -1;

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
    // Blended materials only: 0 = alpha-blended, 1 = additive (seed 001's "additiveness"),
    // composited without sorting by weighted blended OIT (render/oit).
    float additiveness = 0.0f;
};

struct Texture {
    std::string name;
    uint32_t width = 0, height = 0;
    std::vector<uint8_t> rgba8; // width*height*4, top row first
    bool srgb = false;          // base colour and emissive are sRGB, the rest linear
};

struct Instance {
    std::string name;
    uint32_t mesh = 0;
    glm::mat4 transform{1.0f}; // object to world
};

enum class LightType : uint32_t { Directional = 0, Point = 1, Spot = 2 };

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
};

struct Camera {
    std::string name;
    glm::vec3 position{0.0f};
    glm::vec3 forward{0, 0, -1};
    glm::vec3 up{0, 1, 0};
    float yfov = 0.8f; // radians
    float znear = 0.05f;
    float zfar = 500.0f;
};

struct Scene {
    std::string name;
    std::vector<Mesh> meshes;
    std::vector<Material> materials;
    std::vector<Texture> textures;
    std::vector<Instance> instances;
    std::vector<Light> lights;
    std::vector<Camera> cameras; // the first is the default
    glm::vec3 skyColor{0.55f, 0.7f, 0.95f};
    glm::vec3 ambientColor{0.08f, 0.09f, 0.11f};

    Aabb worldBounds() const;
    uint64_t triangleCount() const; // over instances
};

} // namespace shadel
