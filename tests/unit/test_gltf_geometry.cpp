// glTF geometry encodings: sparse accessors (values substituted over a base or over zeros) and
// KHR_mesh_quantization (integer positions, normalized normals and UVs).
#include <gtest/gtest.h>

#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
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
    return importGltfBytes(std::vector<uint8_t>(text.begin(), text.end()), "/tmp/geometry.gltf");
}

nlohmann::json document(const std::vector<uint8_t>& buffer) {
    return {{"asset", {{"version", "2.0"}}},
            {"scenes", {{{"nodes", {0}}}}},
            {"nodes", {{{"mesh", 0}}}},
            {"buffers",
             {{{"byteLength", buffer.size()},
               {"uri", "data:application/octet-stream;base64," + base64(buffer)}}}}};
}

} // namespace

TEST(GltfGeometry, SparseAccessorsSubstituteValuesOverBaseAndOverZeros) {
    std::vector<uint8_t> b;
    append<float>(b, {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}); // 0..48: a unit square
    append<uint16_t>(b, {2});                               // 48..52: sparse index (padded)
    append<float>(b, {3, 4, 0});                            // 52..64: vertex 2 moves
    append<uint16_t>(b, {0, 1, 2, 0, 2, 3});                // 64..76: triangles
    append<uint8_t>(b, {1, 3});                             // 76..80: sparse indices (zeros)
    append<float>(b, {0, 0, 1, 0, 0, 1});                   // 80..104: normals for 1 and 3
    nlohmann::json doc = document(b);
    doc["bufferViews"] = {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}},
                          {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 2}},
                          {{"buffer", 0}, {"byteOffset", 52}, {"byteLength", 12}},
                          {{"buffer", 0}, {"byteOffset", 64}, {"byteLength", 12}},
                          {{"buffer", 0}, {"byteOffset", 76}, {"byteLength", 2}},
                          {{"buffer", 0}, {"byteOffset", 80}, {"byteLength", 24}}};
    doc["accessors"] = {
        {{"bufferView", 0},
         {"componentType", 5126},
         {"count", 4},
         {"type", "VEC3"},
         {"sparse",
          {{"count", 1},
           {"indices", {{"bufferView", 1}, {"componentType", 5123}}},
           {"values", {{"bufferView", 2}}}}}},
        {{"bufferView", 3}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}},
        // No bufferView: zeros with two sparse values (normals of vertices 1 and 3 only).
        {{"componentType", 5126},
         {"count", 4},
         {"type", "VEC3"},
         {"sparse",
          {{"count", 2},
           {"indices", {{"bufferView", 4}, {"componentType", 5121}}},
           {"values", {{"bufferView", 5}}}}}}};
    doc["meshes"] = {
        {{"primitives", {{{"attributes", {{"POSITION", 0}, {"NORMAL", 2}}}, {"indices", 1}}}}}};
    Scene s = importJson(doc);
    ASSERT_EQ(s.meshes.size(), 1u);
    const Mesh& m = s.meshes[0];
    EXPECT_EQ(m.vertices[2].position, glm::vec3(3, 4, 0));
    EXPECT_EQ(m.vertices[1].position, glm::vec3(1, 0, 0));
    EXPECT_EQ(m.vertices[1].normal, glm::vec3(0, 0, 1));
    EXPECT_EQ(m.vertices[3].normal, glm::vec3(0, 0, 1));
    EXPECT_EQ(sceneInvariantViolation(s), ""); // zero normals of 0 and 2 were repaired

    // A sparse index beyond the accessor is an error, not a write out of bounds.
    doc["accessors"][2]["sparse"]["indices"]["componentType"] = 5123; // reads 0x0301 = 769
    EXPECT_THROW(importJson(doc), InputError);
}

TEST(GltfGeometry, QuantizedAttributesDecodeToTheirValues) {
    std::vector<uint8_t> b;
    append<int16_t>(b, {0, 0, 0, 0, 100, 0, 0, 0, 100, 100, 0, 0}); // 0..24 positions (padded)
    append<int8_t>(b, {0, 127, 0, 0, 0, 127, 0, 0, 0, 127, 0, 0});  // 24..36 normals (padded)
    append<uint16_t>(b, {0, 0, 65535, 0, 65535, 65535});            // 36..48 UVs
    append<uint8_t>(b, {0, 1, 2});                                  // 48..52 indices
    nlohmann::json doc = document(b);
    doc["extensionsUsed"] = {"KHR_mesh_quantization"};
    doc["extensionsRequired"] = {"KHR_mesh_quantization"};
    doc["bufferViews"] = {
        {{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 24}, {"byteStride", 8}},
        {{"buffer", 0}, {"byteOffset", 24}, {"byteLength", 12}, {"byteStride", 4}},
        {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 12}},
        {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 3}}};
    doc["accessors"] = {
        {{"bufferView", 0}, {"componentType", 5122}, {"count", 3}, {"type", "VEC3"}},
        {{"bufferView", 1},
         {"componentType", 5120},
         {"normalized", true},
         {"count", 3},
         {"type", "VEC3"}},
        {{"bufferView", 2},
         {"componentType", 5123},
         {"normalized", true},
         {"count", 3},
         {"type", "VEC2"}},
        {{"bufferView", 3}, {"componentType", 5121}, {"count", 3}, {"type", "SCALAR"}}};
    doc["meshes"] = {{{"primitives",
                       {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}}},
                         {"indices", 3}}}}}};
    // The node's scale dequantizes, as gltfpack writes it.
    doc["nodes"][0]["scale"] = {0.01, 0.01, 0.01};
    Scene s = importJson(doc);
    const Mesh& m = s.meshes[0];
    EXPECT_EQ(m.vertices[1].position, glm::vec3(100, 0, 0));
    EXPECT_EQ(m.vertices[2].uv0, glm::vec2(1, 1));
    EXPECT_NEAR(m.vertices[0].normal.y, 1.0f, 1e-6f);
    glm::vec3 world = glm::vec3(s.instances[0].transform * glm::vec4(m.vertices[2].position, 1));
    EXPECT_NEAR(glm::distance(world, glm::vec3(1, 1, 0)), 0.0f, 1e-5f);
}

TEST(GltfGeometry, AnimationsArePosedAtTheRequestedTime) {
    std::vector<uint8_t> b;
    append<float>(b, {0, 0, 0, 1, 0, 0, 0, 1, 0}); // 0..36: a triangle
    append<float>(b, {0, 2});                      // 36..44: key times
    append<float>(b, {0, 0, 0, 4, 0, 0});          // 44..68: translations
    nlohmann::json doc = document(b);
    doc["bufferViews"] = {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
                          {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 8}},
                          {{"buffer", 0}, {"byteOffset", 44}, {"byteLength", 24}}};
    doc["accessors"] = {
        {{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}},
        {{"bufferView", 1}, {"componentType", 5126}, {"count", 2}, {"type", "SCALAR"}},
        {{"bufferView", 2}, {"componentType", 5126}, {"count", 2}, {"type", "VEC3"}}};
    doc["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}};
    doc["nodes"][0]["translation"] = {0, 7, 0}; // the rest pose
    doc["animations"] = {
        {{"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}}}},
         {"samplers", {{{"input", 1}, {"output", 2}, {"interpolation", "LINEAR"}}}}}};
    auto at = [&](std::optional<double> time) {
        std::string text = doc.dump();
        SceneFileOptions o;
        o.time = time;
        Scene s = importGltfBytes(std::vector<uint8_t>(text.begin(), text.end()), "/tmp/a.gltf", o);
        return glm::vec3(s.instances[0].transform[3]);
    };
    EXPECT_EQ(at(std::nullopt), glm::vec3(0, 7, 0));
    EXPECT_EQ(at(0.5), glm::vec3(1, 0, 0));
    EXPECT_EQ(at(9.0), glm::vec3(4, 0, 0)); // after the last key: the last value
    doc["animations"][0]["samplers"][0]["interpolation"] = "STEP";
    EXPECT_EQ(at(1.5), glm::vec3(0, 0, 0));
    // Key times read from a VEC3 accessor are malformed (one InputError, not a misread).
    doc["animations"][0]["samplers"][0]["input"] = 2;
    EXPECT_THROW(at(0.5), InputError);
}
