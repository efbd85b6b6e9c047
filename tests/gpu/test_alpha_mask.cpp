// Alpha-masked materials (glTF alphaMode MASK): the depth prepass, the visibility prepass and
// every shadow map test the mask, in both paths. Scenes without masked materials draw those
// passes with the test compiled out (Renderer::alphaMasked), so the test here is what keeps the
// masked path honest.
#include "gpu_test_env.h"

using namespace shadel;
using namespace shadel::test;

namespace {

enum class Wall { None, Masked, Opaque };

// A floor, a red box, and between the camera and the box a thin wall (alpha `wallAlpha`) whose
// sun shadow falls on the floor in front of the box. `wall`: left out, alpha-masked (cutoff
// 0.5) or opaque.
std::string maskedWallScene(const std::string& name, Wall wall, float wallAlpha) {
    std::vector<float> f, normals;
    std::vector<uint16_t> indices;
    const float floorCentre[3] = {0.0f, -0.05f, 0.0f}, floorHalf[3] = {6.0f, 0.05f, 6.0f};
    const float boxCentre[3] = {0.0f, 0.5f, -1.5f}, boxHalf[3] = {0.5f, 0.5f, 0.5f};
    const float wallCentre[3] = {0.0f, 0.9f, 0.5f}, wallHalf[3] = {1.2f, 0.9f, 0.02f};
    appendBox(floorCentre, floorHalf, f, normals, indices);
    appendBox(boxCentre, boxHalf, f, normals, indices);
    appendBox(wallCentre, wallHalf, f, normals, indices);
    // Each box is its own mesh: positions of all three, then their normals, then indices.
    f.insert(f.end(), normals.begin(), normals.end());
    using nlohmann::json;
    const size_t positionBytes = 3 * 24 * 3 * 4, ib = f.size() * 4;
    json doc;
    doc["asset"] = {{"version", "2.0"}};
    doc["scene"] = 0;
    json nodes = {0, 1, 3, 4};
    if (wall != Wall::None) nodes.push_back(2);
    doc["scenes"] = {{{"nodes", nodes}}};
    doc["extensionsUsed"] = {"KHR_lights_punctual"};
    doc["extensions"]["KHR_lights_punctual"]["lights"] = {
        {{"type", "directional"}, {"intensity", 3.0}, {"color", {1, 1, 1}}}};
    glm::vec3 eye(0.4f, 1.6f, 4.0f), target(0.0f, 0.5f, -1.0f);
    doc["nodes"] = {{{"mesh", 0}, {"name", "floor"}},
                    {{"mesh", 1}, {"name", "red box"}},
                    {{"mesh", 2}, {"name", "wall"}},
                    {{"name", "sun"},
                     {"rotation", gltfRotationTowards(glm::vec3(0.3f, -0.7f, -0.6f))},
                     {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}},
                    {{"name", "camera"},
                     {"camera", 0},
                     {"translation", {eye.x, eye.y, eye.z}},
                     {"rotation", gltfRotationTowards(target - eye)}}};
    doc["cameras"] = {{{"type", "perspective"},
                       {"perspective", {{"yfov", 0.8}, {"znear", 0.05}, {"zfar", 100.0}}}}};
    json views, accessors;
    const int f32 = 5126, u16 = 5123;
    for (int m = 0; m < 3; ++m) {
        views.push_back(gltfBufferView(size_t(m) * 288, 288));                 // positions
        views.push_back(gltfBufferView(positionBytes + size_t(m) * 288, 288)); // normals
        views.push_back(gltfBufferView(ib + size_t(m) * 72, 72));              // indices
        accessors.push_back(gltfAccessor(3 * m, f32, 24, "VEC3"));
        accessors.push_back(gltfAccessor(3 * m + 1, f32, 24, "VEC3"));
        accessors.push_back(gltfAccessor(3 * m + 2, u16, 36, "SCALAR"));
        const float* c = m == 0 ? floorCentre : m == 1 ? boxCentre : wallCentre;
        const float* h = m == 0 ? floorHalf : m == 1 ? boxHalf : wallHalf;
        accessors[3 * m]["min"] = {c[0] - h[0], c[1] - h[1], c[2] - h[2]};
        accessors[3 * m]["max"] = {c[0] + h[0], c[1] + h[1], c[2] + h[2]};
    }
    doc["bufferViews"] = views;
    doc["accessors"] = accessors;
    auto material = [](json colour) {
        return json{
            {"pbrMetallicRoughness",
             {{"baseColorFactor", colour}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.7}}}};
    };
    json wallMaterial = material({0.2, 0.4, 0.9, wallAlpha});
    if (wall == Wall::Masked) wallMaterial["alphaMode"] = "MASK", wallMaterial["alphaCutoff"] = 0.5;
    doc["materials"] = {material({0.8, 0.8, 0.8, 1.0}), material({0.9, 0.1, 0.1, 1.0}),
                        wallMaterial};
    doc["meshes"] = json::array();
    for (int m = 0; m < 3; ++m)
        doc["meshes"].push_back({{"primitives",
                                  {{{"attributes", {{"POSITION", 3 * m}, {"NORMAL", 3 * m + 1}}},
                                    {"indices", 3 * m + 2},
                                    {"material", m}}}}});
    return writeGltf(name, doc, f, indices);
}

} // namespace

// A wall whose alpha is under the cutoff vanishes, and so does its sun shadow; above the cutoff
// it stands as an opaque wall would. Forward (depth prepass) and decoupled (visibility prepass,
// compute marking) both.
TEST(AlphaMask, MaskedSurfacesAndTheirShadowsFollowTheCutoff) {
    std::string none = maskedWallScene("mask_none", Wall::None, 1.0f);
    std::string cut = maskedWallScene("mask_cut", Wall::Masked, 0.2f);
    std::string kept = maskedWallScene("mask_kept", Wall::Masked, 0.8f);
    std::string opaque = maskedWallScene("mask_opaque", Wall::Opaque, 0.8f);
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        SCOPED_TRACE(mode == RenderMode::Forward ? "forward" : "decoupled");
        auto render = [&](const std::string& scene) {
            RenderOptions o = renderOptions(scene, mode, 192, 108);
            o.progress = false;
            return renderChecked(o).frames.back().rgba;
        };
        std::vector<uint8_t> withoutWall = render(none), cutWall = render(cut),
                             keptWall = render(kept), opaqueWall = render(opaque);
        double cutVsNone = psnr(cutWall, withoutWall), keptVsNone = psnr(keptWall, withoutWall),
               keptVsOpaque = psnr(keptWall, opaqueWall);
        std::printf("[ figures ] alpha mask: cut vs no wall %.2f dB, kept vs no wall %.2f dB, "
                    "kept vs opaque %.2f dB\n",
                    cutVsNone, keptVsNone, keptVsOpaque);
        EXPECT_GE(cutVsNone, 50.0) << "a wall under the cutoff (or its shadow) still shows";
        EXPECT_LT(keptVsNone, 25.0) << "the wall above the cutoff should hide the box";
        EXPECT_GE(keptVsOpaque, 50.0) << "above the cutoff a masked wall is an opaque wall";
    }
}
