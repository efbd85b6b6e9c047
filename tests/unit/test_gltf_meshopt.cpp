// EXT_meshopt_compression (scene/gltf_meshopt.h): a gltfpack -cc file decodes to the geometry of
// its source, and every hostile variation of the extension is one InputError, never a crash or
// an allocation the file's size does not justify.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "scene/gltf_import.h"
#include "scene/load.h"
#include "scene/mesh_utils.h"

using namespace shadel;

namespace {

const std::string kData = std::string(SHADEL_SOURCE_DIR) + "/tests/data/gltf";

std::vector<uint8_t> readBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

uint32_t u32(const std::vector<uint8_t>& b, size_t at) {
    uint32_t v;
    std::memcpy(&v, &b[at], 4);
    return v;
}

// The GLB's JSON chunk, and the GLB rebuilt around an edited one.
nlohmann::json glbJson(const std::vector<uint8_t>& glb) {
    return nlohmann::json::parse(glb.begin() + 20, glb.begin() + 20 + long(u32(glb, 12)));
}
std::vector<uint8_t> withJson(const std::vector<uint8_t>& glb, const nlohmann::json& doc) {
    std::string text = doc.dump();
    while (text.size() % 4) text.push_back(' ');
    std::vector<uint8_t> out(glb.begin(), glb.begin() + 12);
    uint32_t chunk = uint32_t(text.size()), type = 0x4E4F534A;
    out.resize(20);
    std::memcpy(&out[12], &chunk, 4);
    std::memcpy(&out[16], &type, 4);
    out.insert(out.end(), text.begin(), text.end());
    out.insert(out.end(), glb.begin() + 20 + long(u32(glb, 12)), glb.end());
    uint32_t length = uint32_t(out.size());
    std::memcpy(&out[8], &length, 4);
    return out;
}

std::vector<glm::vec3> worldPositions(const Scene& s) {
    std::vector<glm::vec3> out;
    for (const Instance& inst : s.instances)
        for (uint32_t i : s.meshes[inst.mesh].indices)
            out.push_back(glm::vec3(inst.transform *
                                    glm::vec4(s.meshes[inst.mesh].vertices[i].position, 1.0f)));
    return out;
}

std::string errorOf(const std::vector<uint8_t>& glb) {
    try {
        importGltfBytes(glb, "hostile.glb");
    } catch (const InputError& e) {
        return e.what();
    }
    return {};
}

} // namespace

TEST(GltfMeshopt, CompressedQuadDecodesToTheOriginalGeometry) {
    // quad_meshopt.glb = gltfpack -cc quad.glb: positions quantized to 14 bits
    // (KHR_mesh_quantization), normals octahedral-filtered, indices TRIANGLES-coded.
    Scene original = loadScene(kData + "/quad.glb");
    Scene packed = loadScene(kData + "/quad_meshopt.glb");
    EXPECT_EQ(sceneInvariantViolation(packed), "");
    ASSERT_EQ(packed.triangleCount(), original.triangleCount());
    std::vector<glm::vec3> a = worldPositions(original), b = worldPositions(packed);
    ASSERT_EQ(a.size(), b.size());
    // Triangles may be rotated or reordered: every corner of the packed quad is a corner of
    // the original within the 14-bit quantization step of its 2 m extent.
    for (glm::vec3 p : b) {
        float nearest = 1e9f;
        for (glm::vec3 q : a) nearest = std::min(nearest, glm::distance(p, q));
        EXPECT_LT(nearest, 2.0f / 16383.0f * 2.0f) << p.x << "," << p.y << "," << p.z;
    }
    for (const Vertex& v : packed.meshes[packed.instances[0].mesh].vertices)
        EXPECT_GT(v.normal.y, 0.99f);
}

TEST(GltfMeshopt, HostileExtensionDataIsOneInputError) {
    const std::vector<uint8_t> glb = readBytes(kData + "/quad_meshopt.glb");
    ASSERT_EQ(errorOf(glb), "");
    const std::string ext = "EXT_meshopt_compression";
    struct Case {
        const char* what;
        std::function<void(nlohmann::json&)> edit;
        const char* reason;
    };
    const Case cases[] = {
        {"a fallback far larger than its compressed data could decode to",
         [&](nlohmann::json& d) { d["buffers"][1]["byteLength"] = 4000000000ull; },
         "more than 128:1"},
        {"truncated compressed stream",
         [&](nlohmann::json& d) { d["bufferViews"][0]["extensions"][ext]["byteLength"] = 7; },
         "meshoptimizer could not decode it"},
        {"compressed bytes beyond their buffer",
         [&](nlohmann::json& d) { d["bufferViews"][2]["extensions"][ext]["byteOffset"] = 119; },
         "exceed buffer 0"},
        {"more elements than the view holds",
         [&](nlohmann::json& d) { d["bufferViews"][0]["extensions"][ext]["count"] = 400; },
         "exceed buffer view 0"},
        {"unknown mode",
         [&](nlohmann::json& d) { d["bufferViews"][0]["extensions"][ext]["mode"] = "ZIP"; },
         "must be ATTRIBUTES, TRIANGLES or INDICES"},
        {"unknown filter",
         [&](nlohmann::json& d) { d["bufferViews"][1]["extensions"][ext]["filter"] = "X"; },
         "must be NONE, OCTAHEDRAL"},
        {"bad index stride",
         [&](nlohmann::json& d) { d["bufferViews"][2]["extensions"][ext]["byteStride"] = 3; },
         "is not valid for mode TRIANGLES"},
        {"source buffer out of range",
         [&](nlohmann::json& d) { d["bufferViews"][0]["extensions"][ext]["buffer"] = 9; },
         "index 9 out of range"},
        {"wrongly typed count",
         [&](nlohmann::json& d) { d["bufferViews"][0]["extensions"][ext]["count"] = "4"; },
         "count: must be a non-negative integer"},
        {"triangle count not a multiple of 3",
         [&](nlohmann::json& d) { d["bufferViews"][2]["extensions"][ext]["count"] = 5; },
         "multiple of 3"},
    };
    for (const Case& c : cases) {
        nlohmann::json doc = glbJson(glb);
        c.edit(doc);
        std::string err = errorOf(withJson(glb, doc));
        EXPECT_NE(err.find(c.reason), std::string::npos) << c.what << ": '" << err << "'";
        EXPECT_EQ(err.rfind("hostile.glb: ", 0), 0u) << c.what << ": " << err;
    }
}
