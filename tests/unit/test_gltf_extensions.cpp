// The required-extension rule (scene/gltf_extensions.h): a required extension we do not support
// is an InputError naming it; optional unsupported ones are one warning listing each once.
#include <gtest/gtest.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "scene/gltf_extensions.h"
#include "scene/gltf_import.h"
#include "scene/load.h"

using namespace shadel;

namespace {
const std::string kData = std::string(SHADEL_SOURCE_DIR) + "/tests/data";

size_t occurrences(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}
} // namespace

TEST(GltfExtensions, SupportedListIsWhatTheImporterApplies) {
    EXPECT_TRUE(gltfExtensionSupported("KHR_lights_punctual"));
    EXPECT_TRUE(gltfExtensionSupported("KHR_mesh_quantization"));
    EXPECT_FALSE(gltfExtensionSupported("KHR_draco_mesh_compression"));
    EXPECT_FALSE(gltfExtensionSupported("KHR_technique_webgl"));
    EXPECT_FALSE(gltfExtensionSupported(""));
}

TEST(GltfExtensions, RequiredUnsupportedIsAnInputErrorNamingIt) {
    const std::string path = kData + "/bad/required_unsupported_extension.gltf";
    try {
        loadScene(path);
        FAIL() << "loaded";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()),
                  path + ": required extension EXT_made_up_geometry is not supported");
    }
    // A required extension that is supported is not an error.
    nlohmann::json doc = {{"extensionsRequired", {"KHR_mesh_quantization"}}};
    EXPECT_NO_THROW(checkRequiredGltfExtensions(doc, "x.gltf"));
}

TEST(GltfExtensions, OptionalUnsupportedAreOneWarningListingEachOnce) {
    ::testing::internal::CaptureStderr();
    loadScene(kData + "/gltf/optional_extensions.gltf");
    std::string err = ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(occurrences(err, "not supported"), 1u) << err;
    EXPECT_NE(err.find("extensions not supported, ignored (the scene may look different): "
                       "EXT_made_up_a, EXT_made_up_b, EXT_made_up_c, EXT_made_up_d"),
              std::string::npos)
        << err;
    for (const char* name : {"EXT_made_up_a", "EXT_made_up_b", "EXT_made_up_c", "EXT_made_up_d"})
        EXPECT_EQ(occurrences(err, name), 1u) << name << " in: " << err;
    EXPECT_EQ(occurrences(err, "KHR_lights_punctual"), 0u) << err;
}

namespace {
const std::string kAssimp = "/usr/share/assimp/models/glTF2";

const Material& materialNamed(const Scene& s, const std::string& name) {
    for (const Material& m : s.materials)
        if (m.name == name) return m;
    throw std::runtime_error("no material " + name);
}
} // namespace

TEST(GltfExtensions, TextureTransformFollowsTheExtensionsMatrix) {
    Scene s = loadScene(kAssimp + "/textureTransform/TextureTransformTest.gltf");
    auto apply = [](const UvTransform& t, glm::vec2 uv) {
        return t.c0 * uv.x + t.c1 * uv.y + t.c2;
    };
    const UvTransform& offset = materialNamed(s, "Offset UV").uvTransforms[0];
    EXPECT_NEAR(glm::distance(apply(offset, {0.25f, 0.1f}), glm::vec2(0.75f, 0.6f)), 0.0f, 1e-6f);
    // Rotation by r: columns (cos r, -sin r), (sin r, cos r) (the render test's markers agree).
    const UvTransform& rot = materialNamed(s, "Rotation").uvTransforms[0];
    float r = 0.39269908f;
    EXPECT_NEAR(glm::distance(apply(rot, {1, 0}), glm::vec2(std::cos(r), -std::sin(r))), 0.0f,
                1e-6f);
    const UvTransform& all = materialNamed(s, "All").uvTransforms[0];
    glm::vec2 expected = glm::vec2(-0.2f, -0.1f) + 1.5f * glm::vec2(std::sin(0.3f), std::cos(0.3f));
    EXPECT_NEAR(glm::distance(apply(all, {0, 1}), expected), 0.0f, 1e-6f);
    // The file's sampler clamps; the untransformed materials keep the identity.
    const TextureSampler& clamped = materialNamed(s, "Offset U").samplers[0];
    EXPECT_EQ(clamped.wrapS, SAMPLER_WRAP_CLAMP_TO_EDGE);
    EXPECT_EQ(clamped.wrapT, SAMPLER_WRAP_CLAMP_TO_EDGE);
    const UvTransform& none = materialNamed(s, "Correct").uvTransforms[0];
    EXPECT_EQ(apply(none, {0.3f, 0.7f}), glm::vec2(0.3f, 0.7f));
}

TEST(GltfExtensions, ClearcoatFactorsAndTextures) {
    Scene s = loadScene(kAssimp + "/ClearCoat-glTF/ClearCoatTest.gltf");
    const Material& simple = materialNamed(s, "Simple_Coated");
    EXPECT_FLOAT_EQ(simple.clearcoatFactor, 1.0f);
    EXPECT_FLOAT_EQ(simple.clearcoatRoughnessFactor, 0.03f);
    EXPECT_EQ(simple.clearcoatTexture, kNoTexture);
    EXPECT_EQ(materialNamed(s, "Simple_Base").clearcoatFactor, 0.0f);
    EXPECT_NE(materialNamed(s, "Partial_Coated").clearcoatTexture, kNoTexture);
    EXPECT_NE(materialNamed(s, "RoughVariations_Coated").clearcoatRoughnessTexture, kNoTexture);
    EXPECT_NE(materialNamed(s, "CoatNorm_Coated").clearcoatNormalTexture, kNoTexture);
    EXPECT_EQ(materialNamed(s, "CoatNorm_Coated").normalTexture, kNoTexture);
}

TEST(GltfExtensions, SpecularGlossinessBecomesMetalRoughWithSpecularColour) {
    Scene s = loadScene(kAssimp + "/BoxTextured-glTF-pbrSpecularGlossiness/BoxTextured.gltf");
    ASSERT_EQ(s.materials.size(), 1u);
    const Material& m = s.materials[0];
    EXPECT_EQ(m.metallicFactor, 0.0f);
    EXPECT_NEAR(m.roughnessFactor, 0.0f, 1e-6f); // glossiness 1
    EXPECT_NE(m.baseColorTexture, kNoTexture);   // the diffuse texture
    // F0 = ((ior-1)/(ior+1))^2 x colour = 0.04 x (0.2 / 0.04) = the specular factor 0.2.
    float r = (m.ior - 1.0f) / (m.ior + 1.0f);
    EXPECT_NEAR(r * r * m.specularColorFactor.x * m.specularFactor, 0.2f, 1e-5f);
}

TEST(GltfExtensions, IorSpecularSheenUnlitFactorsAreRead) {
    nlohmann::json doc = nlohmann::json::parse(R"({
      "asset": {"version": "2.0"},
      "extensionsUsed": ["KHR_materials_ior", "KHR_materials_specular", "KHR_materials_sheen",
                         "KHR_materials_unlit"],
      "materials": [{"extensions": {
        "KHR_materials_ior": {"ior": 1.8},
        "KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [1, 0.5, 0.25]},
        "KHR_materials_sheen": {"sheenColorFactor": [0.9, 0.1, 0.2], "sheenRoughnessFactor": 0.4},
        "KHR_materials_unlit": {}}}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
      "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
      "bufferViews": [{"buffer": 0, "byteLength": 36}],
      "buffers": [{"byteLength": 36,
        "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]
    })");
    std::string text = doc.dump();
    Scene s = importGltfBytes(std::vector<uint8_t>(text.begin(), text.end()), "/tmp/f.gltf");
    const Material& m = s.materials[0];
    EXPECT_FLOAT_EQ(m.ior, 1.8f);
    EXPECT_FLOAT_EQ(m.specularFactor, 0.5f);
    EXPECT_EQ(m.specularColorFactor, glm::vec3(1, 0.5f, 0.25f));
    EXPECT_EQ(m.sheenColorFactor, glm::vec3(0.9f, 0.1f, 0.2f));
    EXPECT_FLOAT_EQ(m.sheenRoughnessFactor, 0.4f);
    EXPECT_TRUE(m.unlit);
}

// KHR_materials_transmission and KHR_materials_volume: factors as authored; an attenuation
// distance left out is infinite (no attenuation); a volume without transmission is not one.
TEST(GltfExtensions, TransmissionAndVolumeFactorsAreRead) {
    nlohmann::json doc = nlohmann::json::parse(R"({
      "asset": {"version": "2.0"},
      "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_volume"],
      "materials": [
        {"extensions": {
          "KHR_materials_transmission": {"transmissionFactor": 0.75},
          "KHR_materials_volume": {"thicknessFactor": 1.2, "attenuationColor": [0.9, 0.5, 0.2],
                                   "attenuationDistance": 0.6}}},
        {"extensions": {
          "KHR_materials_transmission": {"transmissionFactor": 1},
          "KHR_materials_volume": {"thicknessFactor": 0.5}}},
        {"extensions": {"KHR_materials_volume": {"thicknessFactor": 2}}}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
      "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
      "bufferViews": [{"buffer": 0, "byteLength": 36}],
      "buffers": [{"byteLength": 36,
        "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]
    })");
    std::string text = doc.dump();
    Scene s = importGltfBytes(std::vector<uint8_t>(text.begin(), text.end()), "/tmp/f.gltf");
    ASSERT_EQ(s.materials.size(), 3u);
    const Material& volume = s.materials[0];
    EXPECT_FLOAT_EQ(volume.transmissionFactor, 0.75f);
    EXPECT_FLOAT_EQ(volume.thicknessFactor, 1.2f);
    EXPECT_EQ(volume.attenuationColor, glm::vec3(0.9f, 0.5f, 0.2f));
    EXPECT_FLOAT_EQ(volume.attenuationDistance, 0.6f);
    EXPECT_EQ(volume.transmissionTexture, kNoTexture);
    const Material& clear = s.materials[1];
    EXPECT_FLOAT_EQ(clear.transmissionFactor, 1.0f);
    EXPECT_TRUE(std::isinf(clear.attenuationDistance));
    EXPECT_EQ(clear.attenuationColor, glm::vec3(1.0f));
    const Material& opaque = s.materials[2];
    EXPECT_FLOAT_EQ(opaque.transmissionFactor, 0.0f);
    EXPECT_FLOAT_EQ(opaque.thicknessFactor, 0.0f);
    EXPECT_TRUE(gltfExtensionSupported("KHR_materials_transmission"));
    EXPECT_TRUE(gltfExtensionSupported("KHR_materials_volume"));
}

TEST(GltfExtensions, WrongTypesInMaterialExtensionsAreErrors) {
    nlohmann::json doc = nlohmann::json::parse(R"({
      "asset": {"version": "2.0"},
      "materials": [{"extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": "1"}}}]})");
    std::string text = doc.dump();
    try {
        importGltfBytes(std::vector<uint8_t>(text.begin(), text.end()), "x.gltf");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(
                      "/materials/0/extensions/KHR_materials_clearcoat/clearcoatFactor: must be "
                      "a number"),
                  std::string::npos)
            << e.what();
    }
    doc["materials"][0]["extensions"]["KHR_materials_clearcoat"] = {
        {"clearcoatTexture", {{"index", 7}}}};
    text = doc.dump();
    EXPECT_THROW(importGltfBytes(std::vector<uint8_t>(text.begin(), text.end()), "x.gltf"),
                 InputError); // texture index out of range
}

// Samplers as authored: BoxTextured's (mirrored repeat across, clamp down, linear, nearest-
// mipmap-linear) reach its base colour slot; a texture without a sampler gets glTF's default
// (repeat, linear, trilinear), and the slot indices name the bindless table's samplers.
TEST(GltfExtensions, TextureSamplersAreReadAsAuthored) {
    Scene s = loadScene(kAssimp + "/BoxTextured-glTF/BoxTextured.gltf");
    ASSERT_EQ(s.materials.size(), 1u);
    const TextureSampler& box = s.materials[0].samplers[0];
    EXPECT_EQ(box.wrapS, SAMPLER_WRAP_MIRRORED_REPEAT);
    EXPECT_EQ(box.wrapT, SAMPLER_WRAP_CLAMP_TO_EDGE);
    EXPECT_EQ(box.mag, SAMPLER_MAG_LINEAR);
    EXPECT_EQ(box.min, SAMPLER_MIN_NEAREST_MIPMAP_LINEAR);
    EXPECT_EQ(samplerIndex(box), SAMPLER_MATERIAL_FIRST + ((1u * 3u + 2u) * 2u + 1u) * 6u + 4u);
    TextureSampler unset;
    EXPECT_EQ(samplerIndex(unset), SAMPLER_MATERIAL_DEFAULT);
    TextureSampler last{SAMPLER_WRAP_CLAMP_TO_EDGE, SAMPLER_WRAP_CLAMP_TO_EDGE, SAMPLER_MAG_LINEAR,
                        SAMPLER_MIN_LINEAR_MIPMAP_LINEAR};
    EXPECT_EQ(samplerIndex(last), SAMPLER_COUNT - 1u);
    // The clear-coat test's textures have no sampler: the default.
    Scene coat = loadScene(kAssimp + "/ClearCoat-glTF/ClearCoatTest.gltf");
    for (const Material& m : coat.materials)
        for (const TextureSampler& t : m.samplers)
            EXPECT_EQ(samplerIndex(t), SAMPLER_MATERIAL_DEFAULT);
}
