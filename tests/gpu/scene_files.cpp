#include "scene_files.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

#include <sys/wait.h>

#include "gpu_test_env.h"

namespace shadel::test {

std::string writeSlidingCubeScene(const std::string& name, const SlidingCubeScene& s) {
    std::vector<float> f; // quad positions, normals; cube positions, normals; key times, values
    std::vector<uint16_t> indices(s.quadIndices.begin(), s.quadIndices.end());
    auto push3 = [&](glm::vec3 v) { f.insert(f.end(), {v.x, v.y, v.z}); };
    for (glm::vec3 corner : s.quadCorners) push3(corner);
    for (int i = 0; i < 4; ++i) push3(s.quadNormal);
    std::vector<float> cubeNormals;
    const float cubeCentre[3] = {0.0f, 0.0f, 0.0f}, cubeHalf[3] = {0.5f, 0.5f, 0.5f};
    appendBox(cubeCentre, cubeHalf, f, cubeNormals, indices);
    f.insert(f.end(), cubeNormals.begin(), cubeNormals.end());
    f.insert(f.end(), {0.0f, 2.0f});
    push3(s.cubeFrom);
    push3(s.cubeTo);
    using nlohmann::json;
    auto view = gltfBufferView;
    auto accessor = gltfAccessor;
    size_t ib = f.size() * 4;
    json doc;
    doc["asset"] = {{"version", "2.0"}};
    doc["scene"] = 0;
    doc["scenes"] = {{{"nodes", {0, 1}}}};
    doc["nodes"] = {{{"mesh", 0}, {"name", s.quadName}},
                    {{"mesh", 1},
                     {"name", s.cubeName},
                     {"translation", {s.cubeFrom.x, s.cubeFrom.y, s.cubeFrom.z}}}};
    doc["bufferViews"] = {view(0, 48),  view(48, 48),  view(96, 288), view(384, 288),
                          view(672, 8), view(680, 24), view(ib, 12),  view(ib + 12, 72)};
    const int f32 = 5126, u16 = 5123;
    doc["accessors"] = {accessor(0, f32, 4, "VEC3"),   accessor(1, f32, 4, "VEC3"),
                        accessor(2, f32, 24, "VEC3"),  accessor(3, f32, 24, "VEC3"),
                        accessor(4, f32, 2, "SCALAR"), accessor(5, f32, 2, "VEC3"),
                        accessor(6, u16, 6, "SCALAR"), accessor(7, u16, 36, "SCALAR")};
    // Positions and key times carry their bounds.
    glm::vec3 lo = s.quadCorners[0], hi = s.quadCorners[0];
    for (glm::vec3 c : s.quadCorners) lo = glm::min(lo, c), hi = glm::max(hi, c);
    doc["accessors"][0]["min"] = {lo.x, lo.y, lo.z};
    doc["accessors"][0]["max"] = {hi.x, hi.y, hi.z};
    doc["accessors"][2]["min"] = {-0.5, -0.5, -0.5};
    doc["accessors"][2]["max"] = {0.5, 0.5, 0.5};
    doc["accessors"][4]["min"] = {0.0};
    doc["accessors"][4]["max"] = {2.0};
    doc["materials"] = {s.quadMaterial, s.cubeMaterial};
    doc["meshes"] = {
        {{"primitives",
          {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"indices", 6}, {"material", 0}}}}},
        {{"primitives",
          {{{"attributes", {{"POSITION", 2}, {"NORMAL", 3}}}, {"indices", 7}, {"material", 1}}}}}};
    doc["animations"] = {
        {{"channels", {{{"sampler", 0}, {"target", {{"node", 1}, {"path", "translation"}}}}}},
         {"samplers", {{{"input", 4}, {"output", 5}, {"interpolation", "LINEAR"}}}}}};
    return writeGltf(name, doc, f, indices);
}

std::string writeUniformHdr(const std::string& name, float radiance) {
    std::string path = tempPath(name + ".hdr");
    std::ofstream out(path, std::ios::binary);
    out << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 16 +X 32\n";
    int exponent = 0;
    float mantissa = std::frexp(radiance, &exponent); // radiance = mantissa * 2^exponent
    uint8_t m = uint8_t(std::lround(mantissa * 256.0f));
    uint8_t e = uint8_t(exponent + 128);
    for (int i = 0; i < 16 * 32; ++i) out << m << m << m << e;
    return path;
}

int runShadel(const std::string& env, const std::string& args, std::string& err) {
    std::string errFile = tempPath("run_shadel_stderr.txt");
    std::string cmd =
        env + " timeout 120 " + SHADEL_BINARY + " " + args + " >/dev/null 2>" + errFile;
    int status = std::system(cmd.c_str());
    std::ifstream in(errFile);
    std::stringstream ss;
    ss << in.rdbuf();
    err = ss.str();
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

} // namespace shadel::test
