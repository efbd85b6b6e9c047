// glTF import: real models from Debian's assimp-testmodels load with the expected content, and
// every malformed file (ours in tests/data/bad/, assimp's deliberately broken ones) is one
// InputError line naming the file and the reason, never a crash.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <glm/gtc/type_ptr.hpp>

#include "core/error.h"
#include "scene/gltf_import.h"
#include "scene/load.h"
#include "scene/mesh_utils.h"

using namespace shadel;
namespace fs = std::filesystem;

namespace {

const std::string kData = std::string(SHADEL_SOURCE_DIR) + "/tests/data";
const std::string kAssimp = "/usr/share/assimp/models/glTF2";

// Loads `path` expecting an InputError; returns its message (empty if none was thrown).
std::string loadError(const std::string& path) {
    try {
        loadScene(path);
    } catch (const InputError& e) {
        return e.what();
    }
    return {};
}

void expectInputError(const std::string& path, const std::string& reason) {
    std::string message = loadError(path);
    ASSERT_FALSE(message.empty()) << path << " loaded without an error";
    EXPECT_EQ(message.rfind(path + ": ", 0), 0u)
        << "message does not start with the file: " << message;
    EXPECT_NE(message.find(reason), std::string::npos)
        << "expected '" << reason << "' in: " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "not one line: " << message;
    EXPECT_LT(message.size(), 400u) << message;
}

bool haveAssimpModels() {
    return fs::is_directory(kAssimp);
}

// scripts/setup.sh installs assimp-testmodels, so missing models are a broken setup: the tests
// fail instead of skipping (a skip would pass CI without testing anything).
#define REQUIRE_ASSIMP_MODELS()                                                                    \
    ASSERT_TRUE(haveAssimpModels())                                                                \
        << "assimp-testmodels not installed (" << kAssimp << "): run scripts/setup.sh"

// A scratch directory per test, removed afterwards.
class TempDir {
public:
    TempDir() {
        path_ = fs::temp_directory_path() /
                ("shadel_gltf_test_" +
                 std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
                 ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~TempDir() { fs::remove_all(path_); }
    std::string file(const std::string& name) const { return (path_ / name).string(); }

private:
    fs::path path_;
};

void writeFile(const std::string& path, const void* data, size_t size) {
    std::ofstream out(path, std::ios::binary);
    out.write(static_cast<const char*>(data), std::streamsize(size));
}
void writeFile(const std::string& path, const std::string& text) {
    writeFile(path, text.data(), text.size());
}

glm::vec3 worldGeometricNormal(const Scene& scene, const Instance& inst, size_t triangle) {
    const Mesh& mesh = scene.meshes[inst.mesh];
    glm::vec3 p[3];
    for (int k = 0; k < 3; ++k)
        p[k] =
            glm::vec3(inst.transform *
                      glm::vec4(mesh.vertices[mesh.indices[triangle * 3 + size_t(k)]].position, 1));
    return glm::cross(p[1] - p[0], p[2] - p[0]);
}

} // namespace

// --- malformed input ----------------------------------------------------------------------

struct BadFile {
    const char* file;
    const char* reason;
};

// One per defect; the generator is tests/data/make_test_gltf.py.
const BadFile kOurBadFiles[] = {
    {"absurd_count.gltf", "count 4000000000 is out of range"},
    {"accessor_offset_out_of_bounds.gltf",
     "accessor 2 (4 x VEC2 at offset 28) exceeds buffer view 2"},
    {"accessor_out_of_bounds.gltf", "accessor 0 (400 x VEC3 at offset 0) exceeds buffer view 0"},
    {"attribute_count_mismatch.gltf", "accessor 1 (NORMAL) has 3 elements but POSITION has 4"},
    {"attribute_wrong_type.gltf", "accessor 2 (TEXCOORD_0) is VEC3, expected VEC2"},
    {"bad_alpha_mode.gltf", "/materials/0/alphaMode: must be OPAQUE, MASK or BLEND"},
    {"bad_extension_type.gltf", "/nodes/0/extensions/EXT_whatever: must be an object"},
    {"bad_matrix_size.gltf", "/nodes/0/matrix: must have 16 numbers"},
    {"bad_mode.gltf", "invalid primitive mode 9"},
    {"bad_stride.gltf", "invalid stride 6"},
    {"binary_garbage.gltf", "invalid JSON"},
    {"broken_json.gltf", "invalid JSON"},
    {"buffer_size_mismatch.gltf", "<data URI>"},
    {"bufferview_out_of_bounds.gltf", "/bufferViews/2: byte range 96+4000 exceeds buffer 0"},
    {"cyclic_nodes.gltf", "node 0 is reached twice"},
    {"duplicate_root_node.gltf", "node 0 is reached twice"},
    {"empty.gltf", "empty file"},
    {"float_indices.gltf", "accessor 3 (indices) must be an unsigned"},
    {"glb_bad_length.glb", "truncated"},
    {"glb_buffer_too_long.glb", "byteLength"},
    {"glb_version_1.glb", "binary glTF version 1 is not supported"},
    {"gltf_1_0.gltf", "glTF version '1.0' is not supported"},
    {"huge_number.gltf", "invalid JSON: number overflow"},
    {"index_out_of_range.gltf", "accessor 3 index 9001 out of range (vertex count 4)"},
    {"inf_position.gltf", "accessor 0 (POSITION) element 2 is not finite"},
    {"huge_coordinates.gltf", "the scene reaches 7e+31 units from the origin, beyond the 1e+15"},
    {"field_of_view_over_pi.gltf",
     "/cameras/0/perspective/yfov: 5.7 radians: a field of view must be below pi"},
    {"light_index_out_of_range.gltf", "light: index 3 out of range"},
    {"mesh_index_out_of_range.gltf", "/nodes/0/mesh: index 5 out of range"},
    {"missing_buffer.gltf", "does_not_exist.bin"},
    {"nan_position.gltf", "accessor 0 (POSITION) element 1 is not finite"},
    {"no_asset.gltf", "missing 'asset'"},
    {"no_position.gltf", "has no POSITION"},
    {"no_triangles_no_mesh.gltf", "no triangles"},
    {"required_unsupported_extension.gltf",
     "required extension EXT_made_up_geometry is not supported"},
    {"root_not_object.gltf", "root must be an object"},
    {"scene_index_out_of_range.gltf", "/scene: index 3 out of range"},
    {"self_parent_node.gltf", "node 0 is reached twice"},
    {"shared_child_node.gltf", "node 2 is reached twice"},
    {"truncated.glb", "truncated"},
    {"wrong_type_bool.gltf", "/materials/0/doubleSided: must be a boolean (got string)"},
    {"wrong_type_count.gltf", "/accessors/0/count: must be a non-negative integer (got string)"},
    {"wrong_type_primitives.gltf", "/meshes/0/primitives: must be an array (got object)"},
    {"wrong_type_scene.gltf", "/scene: must be a non-negative integer (got string)"},
    {"zero_quaternion.gltf", "rotation is not a valid quaternion"},
};

class OurBadFiles : public ::testing::TestWithParam<BadFile> {};

TEST_P(OurBadFiles, GiveOneLineInputErrorNamingFileAndReason) {
    expectInputError(kData + "/bad/" + GetParam().file, GetParam().reason);
}

INSTANTIATE_TEST_SUITE_P(GltfImport, OurBadFiles, ::testing::ValuesIn(kOurBadFiles),
                         [](const ::testing::TestParamInfo<BadFile>& info) {
                             std::string name = info.param.file;
                             for (char& c : name)
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return name;
                         });

TEST(GltfImport, EveryBadFileHasAnExpectation) {
    std::set<std::string> listed;
    for (const BadFile& b : kOurBadFiles) listed.insert(b.file);
    for (const auto& entry : fs::directory_iterator(kData + "/bad"))
        EXPECT_TRUE(listed.count(entry.path().filename().string()))
            << entry.path() << " is not tested";
}

// Debian's deliberately malformed models (and the glTF 1.0 ones, which we do not read).
const BadFile kAssimpBadFiles[] = {
    {"glTF2/IndexOutOfRange/IndexOutOfRange.gltf", "index 255 out of range (vertex count 24)"},
    {"glTF2/IndexOutOfRange/AllIndicesOutOfRange.gltf",
     "index 65535 out of range (vertex count 24)"},
    {"glTF2/MissingBin/BoxTextured.gltf", "BoxTextured0.bin"},
    {"glTF2/RecursiveNodes/RecursiveNodes.gltf", "reached twice"},
    {"glTF2/SchemaFailures/sceneWrongType.gltf", "/scene: must be a non-negative integer"},
    {"glTF2/wrongTypes/badArray.gltf", "/meshes/0/primitives: must be an array"},
    {"glTF2/wrongTypes/badExtension.gltf", "KHR_texture_transform: must be an object"},
    {"glTF2/wrongTypes/badNumber.gltf", "/materials/0/normalTexture"},
    {"glTF2/wrongTypes/badObject.gltf", "/materials/0/pbrMetallicRoughness: must be an object"},
    {"glTF2/wrongTypes/badString.gltf", "/scenes/0/name: must be a string"},
    {"glTF2/wrongTypes/badUint.gltf", "baseColorTexture/index: must be a non-negative integer"},
    {"glTF2/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb",
     "(POSITION) element 0 is not finite"},
    {"glTF2/IncorrectVertexArrays/Cube.gltf", "exceeds buffer"},
    {"glTF2/TestNoRootNode/NoScene.gltf", "/scene: index 0 out of range"},
    {"glTF2/TestNoRootNode/SceneWithoutNodes.gltf", "no triangles"},
    {"glTF2/draco/2CylinderEngine.gltf", "required extension KHR_draco_mesh_compression"},
    {"glTF2/BoxTextured-glTF-techniqueWebGL/BoxTextured.gltf",
     "required extension KHR_technique_webgl is not supported"},
    {"glTF/BoxTextured-glTF/BoxTextured.gltf", "glTF version '1.0' is not supported"},
    {"glTF/BoxTextured-glTF-Binary/BoxTextured.glb", "binary glTF version 1 is not supported"},
    {"glTF/CesiumMilkTruck/CesiumMilkTruck.gltf", "glTF version 1 is not supported"},
};

class AssimpBadFiles : public ::testing::TestWithParam<BadFile> {};

TEST_P(AssimpBadFiles, GiveOneLineInputErrorNamingFileAndReason) {
    REQUIRE_ASSIMP_MODELS();
    expectInputError(fs::path(kAssimp).parent_path().string() + "/" + GetParam().file,
                     GetParam().reason);
}

INSTANTIATE_TEST_SUITE_P(GltfImport, AssimpBadFiles, ::testing::ValuesIn(kAssimpBadFiles),
                         [](const ::testing::TestParamInfo<BadFile>& info) {
                             std::string name = info.param.file;
                             for (char& c : name)
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return name;
                         });

TEST(GltfImport, LoadSceneRejectsMissingUnknownAndNonFiles) {
    expectInputError(kData + "/bad/no_such_file.gltf", "file not found");
    expectInputError(kData + "/bad/scene.obj", "unknown scene format");
    TempDir dir;
    fs::create_directories(dir.file("folder.gltf"));
    expectInputError(dir.file("folder.gltf"), "not a regular file");
}

TEST(GltfImport, DeeplyNestedJsonIsRefusedNotRecursedInto) {
    TempDir dir;
    std::string text = R"({"asset": {"version": "2.0"}, "extras": )";
    text += std::string(100000, '[') + std::string(100000, ']') + "}";
    writeFile(dir.file("deep.gltf"), text);
    expectInputError(dir.file("deep.gltf"), "nested deeper than");
}

// --- graceful degradation -----------------------------------------------------------------

TEST(GltfImport, MissingImageLoadsWithoutThatTexture) {
    Scene scene = loadScene(kData + "/gltf/missing_image.gltf");
    ASSERT_EQ(scene.materials.size(), 1u);
    EXPECT_EQ(scene.materials[0].baseColorTexture, kNoTexture);
    EXPECT_TRUE(scene.textures.empty());
    EXPECT_EQ(scene.triangleCount(), 2u);
    EXPECT_EQ(sceneInvariantViolation(scene), "");
}

TEST(GltfImport, UnsupportedExtensionWarnsAndEmissiveStrengthApplies) {
    Scene scene = loadScene(kData + "/gltf/unsupported_extension.gltf");
    ASSERT_EQ(scene.materials.size(), 1u);
    EXPECT_FLOAT_EQ(scene.materials[0].emissiveFactor.x, 4.0f);
    EXPECT_FLOAT_EQ(scene.materials[0].emissiveFactor.y, 2.0f);
    EXPECT_FLOAT_EQ(scene.materials[0].emissiveFactor.z, 1.0f);
}

// Blended materials: extras.additiveness wins, else KHR_materials_emissive_strength s gives
// 1 - 1/s, else 0 (render/oit).
TEST(GltfImport, BlendMaterialsMapOntoAdditiveness) {
    Scene scene = loadScene(kData + "/gltf/additiveness.gltf");
    ASSERT_EQ(scene.materials.size(), 3u);
    EXPECT_EQ(scene.materials[0].alphaMode, AlphaMode::Blend);
    EXPECT_FLOAT_EQ(scene.materials[0].additiveness, 0.75f) << "emissive strength 4";
    EXPECT_FLOAT_EQ(scene.materials[1].additiveness, 0.25f) << "extras.additiveness";
    EXPECT_FLOAT_EQ(scene.materials[2].additiveness, 0.0f) << "plain glass";
    Scene opaque = loadScene(kData + "/gltf/unsupported_extension.gltf");
    EXPECT_FLOAT_EQ(opaque.materials[0].additiveness, 0.0f) << "opaque: strength 4 ignored";
}

// --- content ------------------------------------------------------------------------------

// Local GI volumes: a node whose extras say "shadel_gi_volume": true places one, its
// unit cube in world space; anything else is warned about and ignored, never fatal.
TEST(GltfImport, NodeExtrasPlaceLocalGiVolumes) {
    std::ifstream in(kData + "/gltf/cameras_lights.gltf");
    std::stringstream text;
    text << in.rdbuf();
    std::string gltf = text.str();
    // Four more children of the root (translated by +10 in x): a volume scaled (2, 1, 3) at
    // (0, 1, 0), one switched off, one with a non-boolean flag, one flattened to a plane.
    const std::string volumes =
        R"({"name": "room volume", "translation": [0, 1, 0], "scale": [2, 1, 3],
            "extras": {"shadel_gi_volume": true}},
           {"name": "off", "extras": {"shadel_gi_volume": false}},
           {"name": "not a flag", "extras": {"shadel_gi_volume": "yes"}},
           {"name": "flat", "scale": [1, 0, 1], "extras": {"shadel_gi_volume": true}},)";
    size_t nodes = gltf.find("\"nodes\": [", gltf.find("\"nodes\": [") + 1); // the array
    ASSERT_NE(nodes, std::string::npos);
    size_t first = gltf.find('{', nodes);
    gltf.insert(first, volumes);
    // The inserted nodes come first: old indices shift by 4; the root's children and the
    // scene's root follow.
    size_t rootChildren = gltf.find("\"children\": [", first + volumes.size());
    ASSERT_NE(rootChildren, std::string::npos);
    size_t close = gltf.find(']', rootChildren);
    std::string shifted = "\"children\": [5, 6, 7, 8, 9, 10, 0, 1, 2, 3";
    gltf.replace(rootChildren, close - rootChildren, shifted);
    size_t sceneNodes = gltf.find("\"nodes\": [");
    size_t sceneClose = gltf.find(']', sceneNodes);
    gltf.replace(sceneNodes, sceneClose - sceneNodes, "\"nodes\": [4");
    TempDir dir;
    writeFile(dir.file("volumes.gltf"), gltf);
    Scene scene = loadScene(dir.file("volumes.gltf"));
    ASSERT_EQ(scene.giVolumes.size(), 1u);
    EXPECT_EQ(scene.giVolumes[0].name, "room volume");
    EXPECT_NEAR(glm::distance(scene.giVolumes[0].box.min, glm::vec3(8, 0, -3)), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::distance(scene.giVolumes[0].box.max, glm::vec3(12, 2, 3)), 0.0f, 1e-5f);
    EXPECT_EQ(scene.lights.size(), 3u) << "the file's other content still loads";
}

TEST(GltfImport, CamerasAndPunctualLightsInWorldSpace) {
    Scene scene = loadScene(kData + "/gltf/cameras_lights.gltf");
    EXPECT_EQ(sceneInvariantViolation(scene), "");
    ASSERT_EQ(scene.cameras.size(), 2u);
    const Camera& ortho = scene.cameras[1];
    EXPECT_EQ(ortho.name, "ortho");
    EXPECT_FLOAT_EQ(ortho.orthoHalfHeight, 1.0f);
    EXPECT_FLOAT_EQ(ortho.znear, 0.1f);
    EXPECT_FLOAT_EQ(ortho.zfar, 10.0f);
    EXPECT_NEAR(glm::distance(ortho.position, glm::vec3(10, 0, 0)), 0.0f, 1e-5f);
    const Camera& cam = scene.cameras[0];
    EXPECT_EQ(cam.orthoHalfHeight, 0.0f);
    EXPECT_FALSE(cam.automatic);
    EXPECT_EQ(cam.name, "front");
    EXPECT_NEAR(glm::distance(cam.position, glm::vec3(10, 1, 5)), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::distance(cam.forward, glm::vec3(0, 0, -1)), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::distance(cam.up, glm::vec3(0, 1, 0)), 0.0f, 1e-5f);
    EXPECT_FLOAT_EQ(cam.yfov, 0.7f);
    EXPECT_FLOAT_EQ(cam.znear, 0.1f);
    EXPECT_FLOAT_EQ(cam.zfar, 50.0f);

    ASSERT_EQ(scene.lights.size(), 3u);
    std::map<std::string, Light> byName;
    for (const Light& l : scene.lights) byName[l.name] = l;
    const Light& sun = byName.at("sun");
    EXPECT_EQ(sun.type, LightType::Directional);
    EXPECT_TRUE(sun.castsShadow);
    EXPECT_NEAR(glm::distance(sun.direction, glm::vec3(0, -1, 0)), 0.0f, 1e-4f);
    EXPECT_NEAR(glm::distance(sun.color, glm::vec3(1, 0.9f, 0.8f)), 0.0f, 1e-6f);
    EXPECT_FLOAT_EQ(sun.intensity, 3.0f);
    const Light& bulb = byName.at("bulb");
    EXPECT_EQ(bulb.type, LightType::Point);
    EXPECT_NEAR(glm::distance(bulb.position, glm::vec3(10, 3, 0)), 0.0f, 1e-5f);
    EXPECT_FLOAT_EQ(bulb.range, 10.0f);
    EXPECT_FALSE(bulb.castsShadow);
    const Light& spot = byName.at("spot");
    EXPECT_EQ(spot.type, LightType::Spot);
    EXPECT_NEAR(glm::distance(spot.position, glm::vec3(11, 4, 0)), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::distance(spot.direction, glm::vec3(0, -1, 0)), 0.0f, 1e-4f);
    EXPECT_FLOAT_EQ(spot.innerConeAngle, 0.2f);
    EXPECT_FLOAT_EQ(spot.outerConeAngle, 0.4f);

    // Quad (±1 in XZ) scaled by 2 under a parent translated by +10 in X.
    Aabb bounds = scene.worldBounds();
    EXPECT_NEAR(glm::distance(bounds.min, glm::vec3(8, 0, -2)), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::distance(bounds.max, glm::vec3(12, 0, 2)), 0.0f, 1e-5f);
}

TEST(GltfImport, StripsAndFansBecomeTrianglesLinesBecomeSegments) {
    Scene scene = loadScene(kData + "/gltf/strip_fan_lines.gltf");
    EXPECT_EQ(scene.meshes.size(), 2u);
    EXPECT_EQ(scene.triangleCount(), 4u);
    EXPECT_EQ(sceneInvariantViolation(scene), "");
    // The LINES primitive (4 vertices, non-indexed): two segments, drawn forward.
    ASSERT_EQ(scene.pointLines.size(), 1u);
    EXPECT_TRUE(scene.pointLines[0].lines);
    EXPECT_EQ(scene.pointLines[0].vertices.size(), 4u);
}

// Points and lines are drawn (forward only, render/points_lines): a file with nothing else is a
// renderable scene, no longer "no triangles to render".
TEST(GltfImport, PointsOnlyFilesLoad) {
    Scene points = loadScene(kData + "/gltf/points_only.gltf");
    EXPECT_EQ(points.triangleCount(), 0u);
    ASSERT_EQ(points.pointLines.size(), 1u);
    EXPECT_FALSE(points.pointLines[0].lines);
    EXPECT_FALSE(points.pointLines[0].vertices.empty());
    EXPECT_TRUE(points.worldBounds().valid()); // framing sees them
    REQUIRE_ASSIMP_MODELS();
    // glTF-Asset-Generator's points, lines, line loop and line strip (modes 0-3).
    for (int mode = 0; mode < 4; ++mode) {
        std::string file = kAssimp +
                           "/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_0" +
                           std::to_string(mode) + ".gltf";
        Scene scene = loadScene(file);
        ASSERT_EQ(scene.pointLines.size(), 1u) << file;
        EXPECT_EQ(scene.pointLines[0].lines, mode != 0) << file;
        if (mode != 0) {
            EXPECT_EQ(scene.pointLines[0].vertices.size() % 2, 0u) << file;
        }
    }
}

// A mirroring instance shares its mesh (the renderer draws it with the clockwise front face,
// deciding from the transform every frame): the triangle's world winding turns, and with the
// front face the transform's sign gives, its front side stays up.
TEST(GltfImport, MirroredInstanceSharesItsMeshAndKeepsFrontFacesFront) {
    Scene scene = loadScene(kData + "/gltf/mirrored.gltf");
    ASSERT_EQ(scene.instances.size(), 2u);
    EXPECT_EQ(scene.instances[0].mesh, scene.instances[1].mesh);
    EXPECT_EQ(scene.meshes.size(), 1u);
    for (const Instance& inst : scene.instances) {
        float sign = glm::determinant(glm::mat3(inst.transform)) < 0.0f ? -1.0f : 1.0f;
        EXPECT_GT(sign * glm::dot(worldGeometricNormal(scene, inst, 0), glm::vec3(0, 1, 0)), 0.0f)
            << inst.name;
    }
}

TEST(GltfImport, GlbAndEmbeddedGltfGiveTheSameQuad) {
    Scene glb = loadScene(kData + "/gltf/quad.glb");
    Scene gltf = loadScene(kData + "/gltf/missing_image.gltf");
    ASSERT_EQ(glb.meshes.size(), 1u);
    ASSERT_EQ(glb.meshes[0].vertices.size(), gltf.meshes[0].vertices.size());
    EXPECT_EQ(glb.meshes[0].indices, gltf.meshes[0].indices);
    for (size_t v = 0; v < glb.meshes[0].vertices.size(); ++v)
        EXPECT_EQ(glb.meshes[0].vertices[v].position, gltf.meshes[0].vertices[v].position);
}

// A primitive above 65 535 triangles is split into parts; the geometry is unchanged.
TEST(GltfImport, LargePrimitiveIsSplitForSixteenBitTriangleIds) {
    TempDir dir;
    const uint32_t n = 200; // 200 x 200 quads = 80 000 triangles
    std::vector<float> positions;
    for (uint32_t z = 0; z <= n; ++z)
        for (uint32_t x = 0; x <= n; ++x)
            positions.insert(positions.end(), {float(x), 0.0f, float(z)});
    std::vector<uint32_t> indices;
    for (uint32_t z = 0; z < n; ++z)
        for (uint32_t x = 0; x < n; ++x) {
            uint32_t a = z * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
            indices.insert(indices.end(), {a, c, b, b, c, d});
        }
    std::vector<uint8_t> bin(positions.size() * 4 + indices.size() * 4);
    std::memcpy(bin.data(), positions.data(), positions.size() * 4);
    std::memcpy(bin.data() + positions.size() * 4, indices.data(), indices.size() * 4);
    writeFile(dir.file("grid.bin"), bin.data(), bin.size());
    std::string gltf =
        R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
      "meshes": [{"name": "grid", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
      "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": )" +
        std::to_string(positions.size() / 3) + R"(, "type": "VEC3"},
        {"bufferView": 1, "componentType": 5125, "count": )" +
        std::to_string(indices.size()) + R"(, "type": "SCALAR"}],
      "bufferViews": [
        {"buffer": 0, "byteOffset": 0, "byteLength": )" +
        std::to_string(positions.size() * 4) + R"(},
        {"buffer": 0, "byteOffset": )" +
        std::to_string(positions.size() * 4) + R"(, "byteLength": )" +
        std::to_string(indices.size() * 4) + R"(}],
      "buffers": [{"uri": "grid.bin", "byteLength": )" +
        std::to_string(bin.size()) + "}]}";
    writeFile(dir.file("grid.gltf"), gltf);

    Scene scene = loadScene(dir.file("grid.gltf"));
    EXPECT_EQ(sceneInvariantViolation(scene), "");
    ASSERT_EQ(scene.meshes.size(), 2u);
    ASSERT_EQ(scene.instances.size(), 2u);
    EXPECT_EQ(scene.triangleCount(), 80000u);
    size_t t = 0;
    for (const Mesh& part : scene.meshes) {
        EXPECT_LE(part.triangleCount(), kMaxTrianglesPerMesh);
        for (size_t i = 0; i < part.indices.size(); ++i, ++t)
            ASSERT_EQ(part.vertices[part.indices[i]].position,
                      glm::make_vec3(&positions[indices[t] * 3]));
    }
}

// --- real models (assimp-testmodels) ------------------------------------------------------

TEST(GltfImportModels, BoxTexturedInAllThreeContainersIsTheSame) {
    REQUIRE_ASSIMP_MODELS();
    const char* variants[] = {"BoxTextured-glTF/BoxTextured.gltf",
                              "BoxTextured-glTF-Binary/BoxTextured.glb",
                              "BoxTextured-glTF-Embedded/BoxTextured.gltf"};
    std::vector<Scene> scenes;
    for (const char* v : variants) scenes.push_back(loadScene(kAssimp + "/" + v));
    for (const Scene& s : scenes) {
        EXPECT_EQ(sceneInvariantViolation(s), "");
        ASSERT_EQ(s.meshes.size(), 1u);
        EXPECT_EQ(s.triangleCount(), 12u);
        EXPECT_EQ(s.meshes[0].vertices.size(), 24u);
        Aabb b = s.worldBounds();
        EXPECT_NEAR(glm::distance(b.min, glm::vec3(-0.5f)), 0.0f, 1e-5f);
        EXPECT_NEAR(glm::distance(b.max, glm::vec3(0.5f)), 0.0f, 1e-5f);
        ASSERT_EQ(s.textures.size(), 1u);
        EXPECT_EQ(s.textures[0].width, 211u); // CesiumLogoFlat.png
        EXPECT_EQ(s.textures[0].height, 211u);
        EXPECT_TRUE(s.textures[0].srgb);
        EXPECT_EQ(s.materials[s.meshes[0].material].baseColorTexture, 0);
    }
    for (size_t i = 1; i < scenes.size(); ++i) {
        EXPECT_EQ(scenes[i].meshes[0].indices, scenes[0].meshes[0].indices);
        EXPECT_EQ(scenes[i].textures[0].rgba8, scenes[0].textures[0].rgba8);
        for (size_t v = 0; v < 24; ++v) {
            EXPECT_EQ(scenes[i].meshes[0].vertices[v].position,
                      scenes[0].meshes[0].vertices[v].position);
            EXPECT_EQ(scenes[i].meshes[0].vertices[v].uv0, scenes[0].meshes[0].vertices[v].uv0);
        }
    }
}

TEST(GltfImportModels, TwoCylinderEngineHierarchy) {
    REQUIRE_ASSIMP_MODELS();
    Scene s = loadScene(kAssimp + "/2CylinderEngine-glTF-Binary/2CylinderEngine.glb");
    EXPECT_EQ(sceneInvariantViolation(s), "");
    EXPECT_EQ(s.meshes.size(), 34u);
    EXPECT_EQ(s.instances.size(), 115u);
    EXPECT_EQ(s.triangleCount(), 121496u);
    Aabb b = s.worldBounds();
    EXPECT_GT(b.extent().x, 700.0f); // millimetres: the engine is ~0.75 m long
    EXPECT_LT(b.extent().x, 800.0f);
}

TEST(GltfImportModels, CamerasFile) {
    REQUIRE_ASSIMP_MODELS();
    Scene s = loadScene(kAssimp + "/cameras/Cameras.gltf");
    EXPECT_EQ(sceneInvariantViolation(s), "");
    EXPECT_EQ(s.triangleCount(), 2u);
    ASSERT_EQ(s.cameras.size(), 2u); // one perspective, one orthographic
    EXPECT_FLOAT_EQ(s.cameras[1].orthoHalfHeight, 1.0f);
    EXPECT_NEAR(glm::distance(s.cameras[0].position, glm::vec3(0.5f, 0.5f, 3.0f)), 0.0f, 1e-5f);
    EXPECT_FLOAT_EQ(s.cameras[0].yfov, 0.7f);
    EXPECT_FLOAT_EQ(s.cameras[0].zfar, 100.0f);
    // No normals in the file: computed ones face the camera side of the tilted square.
    EXPECT_GT(s.meshes[0].vertices[0].normal.z, 0.5f);
}

TEST(GltfImportModels, StripAndFanModesKeepConsistentWinding) {
    REQUIRE_ASSIMP_MODELS();
    // Mesh_PrimitiveMode 04..06 and 11..15: triangles, strips and fans (indexed or not), each a
    // 1 x 1 square in the XY plane facing +Z.
    for (int mode : {4, 5, 6, 11, 12, 13, 14, 15}) {
        char name[128];
        std::snprintf(name, sizeof(name),
                      "%s/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_%02d.gltf",
                      kAssimp.c_str(), mode);
        Scene s = loadScene(name);
        EXPECT_EQ(sceneInvariantViolation(s), "") << name;
        EXPECT_EQ(s.triangleCount(), 2u) << name;
        for (size_t t = 0; t < 2; ++t)
            EXPECT_GT(worldGeometricNormal(s, s.instances[0], t).z, 0.0f)
                << name << " triangle " << t;
    }
}

TEST(GltfImportModels, OtherModelsLoadWithValidAttributes) {
    REQUIRE_ASSIMP_MODELS();
    struct Expect {
        const char* file;
        uint64_t triangles;
        size_t textures;
    };
    const Expect models[] = {
        {"BoxTexcoords-glTF/boxTexcoords.gltf", 12, 2},
        {"BoxBadNormals-glTF-Binary/BoxBadNormals.glb", 12, 0},
        {"BoxTextured-glTF-pbrSpecularGlossiness/BoxTextured.gltf", 12, 1},
        {"ClearCoat-glTF/ClearCoatTest.gltf", 37116, 6}, // 5 + the clearcoat weight texture
        {"textureTransform/TextureTransformTest.gltf", 24, 5},
        {"glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf", 12, 0},
        {"simple_skin/simple_skin.gltf", 8, 0},
        {"issue_3269/texcoord_crash.gltf", 10, 1},
    };
    for (const Expect& m : models) {
        Scene s = loadScene(kAssimp + "/" + m.file);
        EXPECT_EQ(sceneInvariantViolation(s), "") << m.file;
        EXPECT_EQ(s.triangleCount(), m.triangles) << m.file;
        EXPECT_EQ(s.textures.size(), m.textures) << m.file;
        EXPECT_FALSE(s.cameras.empty()) << m.file;
        EXPECT_FALSE(s.lights.empty()) << m.file;
    }
}

// A file without a directional light gets "auto-sun" unless --sun off (addDefaultSun); a file
// with one keeps its own lights only.
TEST(GltfImport, DefaultSunOnlyWithoutADirectionalLight) {
    std::ifstream in(kData + "/gltf/cameras_lights.gltf");
    std::stringstream text;
    text << in.rdbuf();
    std::string gltf = text.str();
    auto sunCount = [](const Scene& scene) {
        return std::count_if(scene.lights.begin(), scene.lights.end(),
                             [](const Light& l) { return l.name == "auto-sun"; });
    };
    Scene withSun = loadScene(kData + "/gltf/cameras_lights.gltf");
    EXPECT_EQ(withSun.lights.size(), 3u);
    EXPECT_EQ(sunCount(withSun), 0);
    size_t at = gltf.find("\"directional\"");
    ASSERT_NE(at, std::string::npos);
    gltf.replace(at, std::strlen("\"directional\""), "\"point\"");
    TempDir dir;
    writeFile(dir.file("no_sun.gltf"), gltf);
    Scene pointsOnly = loadScene(dir.file("no_sun.gltf"));
    ASSERT_EQ(pointsOnly.lights.size(), 4u) << "a point light is not a sun";
    EXPECT_EQ(sunCount(pointsOnly), 1);
    EXPECT_EQ(pointsOnly.lights.back().type, LightType::Directional);
    Scene off = loadScene(dir.file("no_sun.gltf"), {.addDefaultSun = false});
    EXPECT_EQ(off.lights.size(), 3u);
    EXPECT_EQ(sunCount(off), 0);
}
