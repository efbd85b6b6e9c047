// glTF's second UV set: TEXCOORD_1 in every accessor encoding glTF allows for it (float,
// normalized unsigned byte, normalized unsigned short) lands in Vertex::uv1; a mesh without it
// gets uv1 = uv0; each material texture slot records the set it reads (texCoord, overridden by
// KHR_texture_transform's texCoord), and a third set is refused with a warning naming the
// material and the slot.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <stb/stb_image_write.h> // defined once, in scene/gltf_import.cpp

#include "scene/gltf_import.h"
#include "scene/mesh_utils.h"

using namespace shadel;

namespace {

std::string base64(const std::vector<uint8_t>& data) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < data.size(); i += 3) {
        uint32_t v = uint32_t(data[i]) << 16;
        if (i + 1 < data.size()) v |= uint32_t(data[i + 1]) << 8;
        if (i + 2 < data.size()) v |= data[i + 2];
        out += table[(v >> 18) & 63];
        out += table[(v >> 12) & 63];
        out += i + 1 < data.size() ? table[(v >> 6) & 63] : '=';
        out += i + 2 < data.size() ? table[v & 63] : '=';
    }
    return out;
}

template <typename T>
void append(std::vector<uint8_t>& buffer, std::initializer_list<T> values) {
    for (T v : values) {
        uint8_t bytes[sizeof(T)];
        std::memcpy(bytes, &v, sizeof(T));
        buffer.insert(buffer.end(), bytes, bytes + sizeof(T));
    }
    while (buffer.size() % 4) buffer.push_back(0);
}

Scene importJson(const nlohmann::json& doc) {
    std::string text = doc.dump();
    return importGltfBytes(std::vector<uint8_t>(text.begin(), text.end()), "/tmp/texcoords.gltf");
}

// A 2 x 2 RGBA PNG as a data URI (the slots need a loadable image to be kept).
std::string pngDataUri() {
    const uint8_t pixels[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
    std::vector<uint8_t> png;
    stbi_write_png_to_func(
        [](void* context, void* data, int size) {
            auto* out = static_cast<std::vector<uint8_t>*>(context);
            out->insert(out->end(), static_cast<uint8_t*>(data),
                        static_cast<uint8_t*>(data) + size);
        },
        &png, 2, 2, 4, pixels, 8);
    return "data:image/png;base64," + base64(png);
}

// One triangle: positions, TEXCOORD_0 (floats (0,0), (1,0), (0,1)), and, when
// `uv1ComponentType` is not 0, TEXCOORD_1 in that encoding holding (0, 0.2), (1, 0), (0.2, 1)
// (exact in every encoding: 51 / 255 and 13107 / 65535 are 0.2).
nlohmann::json triangle(int uv1ComponentType) {
    std::vector<uint8_t> buffer;
    append<float>(buffer, {0, 0, 0, 1, 0, 0, 0, 1, 0}); // 36 bytes
    append<float>(buffer, {0, 0, 1, 0, 0, 1});          // 24 bytes at 36
    size_t uv1Offset = buffer.size();
    int stride = 0;
    if (uv1ComponentType == 5126) {
        append<float>(buffer, {0.0f, 0.2f, 1.0f, 0.0f, 0.2f, 1.0f});
    } else if (uv1ComponentType == 5121) { // elements aligned to 4 bytes (glTF's rule)
        const uint8_t uv[6] = {0, 51, 255, 0, 51, 255};
        for (int v = 0; v < 3; ++v)
            buffer.insert(buffer.end(), {uv[2 * v], uv[2 * v + 1], uint8_t(0), uint8_t(0)});
        stride = 4;
    } else if (uv1ComponentType == 5123) {
        append<uint16_t>(buffer, {0, 13107, 65535, 0, 13107, 65535});
    }
    size_t uv1Bytes = buffer.size() - uv1Offset;
    nlohmann::json doc = {{"asset", {{"version", "2.0"}}},
                          {"scenes", {{{"nodes", {0}}}}},
                          {"nodes", {{{"mesh", 0}}}}};
    doc["bufferViews"] = {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
                          {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 24}}};
    doc["accessors"] = {
        {{"bufferView", 0},
         {"componentType", 5126},
         {"count", 3},
         {"type", "VEC3"},
         {"min", {0, 0, 0}},
         {"max", {1, 1, 0}}},
        {{"bufferView", 1}, {"componentType", 5126}, {"count", 3}, {"type", "VEC2"}}};
    nlohmann::json attributes = {{"POSITION", 0}, {"TEXCOORD_0", 1}};
    if (uv1ComponentType != 0) {
        nlohmann::json view = {{"buffer", 0}, {"byteOffset", uv1Offset}, {"byteLength", uv1Bytes}};
        if (stride) view["byteStride"] = stride;
        doc["bufferViews"].push_back(view);
        nlohmann::json accessor = {
            {"bufferView", 2}, {"componentType", uv1ComponentType}, {"count", 3}, {"type", "VEC2"}};
        if (uv1ComponentType != 5126) accessor["normalized"] = true;
        doc["accessors"].push_back(accessor);
        attributes["TEXCOORD_1"] = 2;
    }
    doc["meshes"] = {{{"primitives", {{{"attributes", attributes}}}}}};
    doc["buffers"] = {{{"byteLength", buffer.size()},
                       {"uri", "data:application/octet-stream;base64," + base64(buffer)}}};
    return doc;
}

} // namespace

TEST(GltfTexcoords, SecondUvSetImportsInEveryEncoding) {
    const glm::vec2 expected[3] = {{0.0f, 0.2f}, {1.0f, 0.0f}, {0.2f, 1.0f}};
    for (int type : {5126, 5121, 5123}) {
        Scene s = importJson(triangle(type));
        ASSERT_EQ(s.meshes.size(), 1u);
        const Mesh& m = s.meshes[0];
        ASSERT_EQ(m.vertices.size(), 3u);
        for (size_t v = 0; v < 3; ++v) {
            EXPECT_NEAR(m.vertices[v].uv1.x, expected[v].x, 1e-6f) << "type " << type << " v" << v;
            EXPECT_NEAR(m.vertices[v].uv1.y, expected[v].y, 1e-6f) << "type " << type << " v" << v;
        }
        EXPECT_EQ(m.vertices[1].uv0, glm::vec2(1, 0)) << "TEXCOORD_0 stays the first set";
        EXPECT_EQ(sceneInvariantViolation(s), "");
    }
}

TEST(GltfTexcoords, MeshWithoutSecondSetReadsTheFirst) {
    Scene s = importJson(triangle(0));
    ASSERT_EQ(s.meshes.size(), 1u);
    for (const Vertex& v : s.meshes[0].vertices) EXPECT_EQ(v.uv1, v.uv0);
}

// Base colour on set 1; metal-roughness on set 0 overridden to 1 by KHR_texture_transform;
// occlusion on set 1 overridden to 0; normal on set 0; emissive on set 2 (not supported: set 0,
// with a warning naming the material and the slot).
TEST(GltfTexcoords, SlotsRecordTheSetTheyRead) {
    nlohmann::json doc = triangle(5126);
    doc["images"] = {{{"uri", pngDataUri()}}};
    doc["textures"] = {{{"source", 0}}};
    auto override = [](int texCoord) {
        return nlohmann::json{{"KHR_texture_transform", {{"texCoord", texCoord}}}};
    };
    doc["extensionsUsed"] = {"KHR_texture_transform"};
    doc["materials"] = {
        {{"name", "two sets"},
         {"pbrMetallicRoughness",
          {{"baseColorTexture", {{"index", 0}, {"texCoord", 1}}},
           {"metallicRoughnessTexture", {{"index", 0}, {"extensions", override(1)}}}}},
         {"occlusionTexture", {{"index", 0}, {"texCoord", 1}, {"extensions", override(0)}}},
         {"normalTexture", {{"index", 0}}},
         {"emissiveTexture", {{"index", 0}, {"texCoord", 2}}}}};
    doc["meshes"][0]["primitives"][0]["material"] = 0;
    testing::internal::CaptureStderr();
    Scene s = importJson(doc);
    std::string log = testing::internal::GetCapturedStderr();
    ASSERT_EQ(s.materials.size(), 1u);
    const Material& m = s.materials[0];
    auto set = [&](TextureSlot slot) { return int(m.texCoords[uint32_t(slot)]); };
    EXPECT_EQ(set(TextureSlot::BaseColor), 1);
    EXPECT_EQ(set(TextureSlot::MetallicRoughness), 1) << "KHR_texture_transform's texCoord";
    EXPECT_EQ(set(TextureSlot::Occlusion), 0) << "KHR_texture_transform's texCoord";
    EXPECT_EQ(set(TextureSlot::Normal), 0);
    EXPECT_EQ(set(TextureSlot::Emissive), 0) << "TEXCOORD_2 is not imported";
    EXPECT_NE(m.emissiveTexture, kNoTexture) << "the texture stays, on the first set";
    EXPECT_NE(log.find("material 'two sets': its emissive texture reads TEXCOORD_2"),
              std::string::npos)
        << log;
    EXPECT_EQ(log.find("only TEXCOORD_0 is imported"), std::string::npos) << log;
    EXPECT_EQ(log.find("base colour texture"), std::string::npos) << "set 1 is supported: " << log;
}
