// glTF points and lines (render/points_lines): drawn forward in both modes, unlit
// (base colour factor x COLOR_0), depth tested against the surfaces.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "gpu_test_env.h"

using namespace shadel;
using namespace shadel::test;
namespace fs = std::filesystem;

namespace {

const std::string kData = std::string(SHADEL_SOURCE_DIR) + "/tests/data";

// tests/data/gltf/points_only.gltf's quad (+-1 in XZ) as `triangles` (mode 4, grey) or nothing,
// plus a red LINE_LOOP around it 0.05 above and red points at its corners, written to scratch.
std::string pointsLinesFile(const std::string& name, bool triangles, bool lines) {
    nlohmann::json doc;
    std::ifstream(kData + "/gltf/points_only.gltf") >> doc;
    doc["materials"].push_back(
        {{"name", "red"}, {"pbrMetallicRoughness", {{"baseColorFactor", {1, 0, 0, 1}}}}});
    nlohmann::json& prim = doc["meshes"][0]["primitives"][0];
    prim["mode"] = triangles ? 4 : 0;
    if (!triangles) prim["material"] = 1;
    nlohmann::json extra = nlohmann::json::array();
    if (lines) extra.push_back({{"attributes", {{"POSITION", 0}}}, {"mode", 2}, {"material", 1}});
    extra.push_back({{"attributes", {{"POSITION", 0}}}, {"mode", 0}, {"material", 1}});
    doc["meshes"].push_back({{"name", "outline"}, {"primitives", extra}});
    doc["nodes"].push_back({{"mesh", 1}, {"translation", {0, 0.05, 0}}});
    doc["scenes"][0]["nodes"].push_back(int(doc["nodes"].size()) - 1);
    fs::path dir = tempPath("points_lines");
    fs::create_directories(dir);
    fs::path file = dir / name;
    std::ofstream(file) << doc.dump();
    return file.string();
}

RenderRun renderAbove(const std::string& file, RenderMode mode) {
    RenderOptions o = renderOptions(file, mode, 160, 90);
    o.progress = false;
    o.cameraOverrides.from = glm::vec3(0.0f, 2.5f, 1.5f);
    o.cameraOverrides.lookAt = glm::vec3(0.0f);
    return renderChecked(o);
}

// Pixels whose red clearly dominates (the unlit red points and lines; the quad is grey).
uint64_t redPixels(const RenderRun& run) {
    const auto& p = run.frames[0].rgba;
    uint64_t n = 0;
    for (size_t i = 0; i + 3 < p.size(); i += 4) n += p[i] > 150 && p[i + 1] < 60 && p[i + 2] < 60;
    return n;
}

} // namespace

TEST(GltfFeaturesPointsLines, PointsAndLinesOnlyFileRendersTheSameInBothModes) {
    std::string file = pointsLinesFile("only.gltf", false, true);
    RenderRun fwd = renderAbove(file, RenderMode::Forward);
    RenderRun dec = renderAbove(file, RenderMode::Decoupled);
    uint64_t red = redPixels(fwd);
    double same = psnr(fwd.frames[0].rgba, dec.frames[0].rgba);
    std::printf("points + lines only: %llu red pixels, %llu covered; decoupled vs forward %.1f "
                "dB\n",
                (unsigned long long)red, (unsigned long long)fwd.frames[0].pixelsCovered, same);
    // A square outline of 1-pixel lines around a quad ~100 px wide: a few hundred pixels.
    EXPECT_GT(red, 100u);
    EXPECT_LT(red, 2000u);
    EXPECT_GT(fwd.stats["points_lines_vertices"].get<uint32_t>(), 0u);
    EXPECT_GE(same, 50.0); // forward in both modes
}

TEST(GltfFeaturesPointsLines, LinesOverASurfaceAgreeBetweenPaths) {
    RenderRun with = renderAbove(pointsLinesFile("with.gltf", true, true), RenderMode::Forward);
    RenderRun without =
        renderAbove(pointsLinesFile("without.gltf", true, false), RenderMode::Forward);
    RenderRun dec = renderAbove(pointsLinesFile("with.gltf", true, true), RenderMode::Decoupled);
    double agree = psnr(with.frames[0].rgba, dec.frames[0].rgba);
    std::printf("quad + outline: %llu red pixels with the line loop, %llu without (points "
                "only); decoupled vs forward %.1f dB\n",
                (unsigned long long)redPixels(with), (unsigned long long)redPixels(without), agree);
    EXPECT_GT(redPixels(with), redPixels(without) + 100);
    EXPECT_GE(agree, 30.0);
    EXPECT_EQ(dec.stats["reconstruction_misses"].get<uint64_t>(), 0u);
}
