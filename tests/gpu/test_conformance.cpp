// Conformance with the Khronos glTF Sample Viewer, the reference implementation of glTF PBR: each
// model of tools/conformance/models.json rendered by shadel (forward and decoupled) at the
// manifest's size from the file's camera "conformance" with the file's light, compared with the
// viewer's image in tests/data/conformance/reference/ (rendered with the committed environment,
// ACES Narkowicz at exposure 1, no shadows, a black background; four times the size, box-filtered,
// against shadel's 4x4 supersampling). PSNR is over the pixels either
// image covers; each model has a floor per mode in the manifest, set from this test's figures
// (tools/conformance/compare.py --floors-from; they are in docs/conformance/gpu_test.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "conformance_oracle.h"

using namespace shadel;
using namespace shadel::test;
namespace fs = std::filesystem;

namespace {

struct Case {
    std::string model;
    RenderMode mode;
};
void PrintTo(const Case& c, std::ostream* os) {
    *os << c.model << (c.mode == RenderMode::Forward ? " forward" : " decoupled");
}

std::vector<Case> cases() {
    std::vector<Case> out;
    const nlohmann::json& m = conformanceManifest();
    if (!m.is_object() || !m.contains("models")) return out;
    for (const auto& model : m["models"])
        for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled})
            out.push_back({model["name"].get<std::string>(), mode});
    return out;
}

class Conformance : public ::testing::TestWithParam<Case> {};

TEST_P(Conformance, MatchesSampleViewer) {
    const Case& c = GetParam();
    nlohmann::json model;
    for (const auto& m : conformanceManifest()["models"])
        if (m["name"] == c.model) model = m;
    SHADEL_REQUIRE(!model.contains("resources") ||
                       fs::exists(model["resources"].get<std::string>()),
                   model["resources"].get<std::string>() << " (the assimp-testmodels package)");
    const char* modeName = c.mode == RenderMode::Forward ? "forward" : "decoupled";
    std::string floorKey = std::string("floor_") + modeName;

    int w = 0, h = 0;
    std::vector<uint8_t> ref = loadConformanceReference(c.model, w, h);
    ASSERT_FALSE(ref.empty()) << "missing reference " << c.model << ".png";
    ASSERT_EQ(uint32_t(w), conformanceManifest()["size"][0].get<uint32_t>());
    ASSERT_EQ(uint32_t(h), conformanceManifest()["size"][1].get<uint32_t>());

    fs::path scene = stageConformanceModel(model);
    RenderRun run = renderChecked(conformanceOptions(scene.string(), c.mode, w, h));
    ASSERT_EQ(run.frames.size(), 1u);
    std::vector<uint8_t> img = run.frames[0].rgba;
    compositeOverBlack(img);
    ASSERT_EQ(img.size(), ref.size());
    fs::remove_all(scene.parent_path());

    ConformanceMeasure m = measureAgainstReference(ref, img);
    std::printf("[ figures ] conformance %s %s: PSNR %.2f dB over %zu covered pixels\n",
                c.model.c_str(), modeName, m.psnr, m.covered);
    // Content first: a blank or flat image must not pass on a lenient floor.
    size_t minCovered = size_t(w) * size_t(h) / 50;
    EXPECT_GE(m.shadelCovered, minCovered) << c.model << ": shadel covers too few pixels";
    EXPECT_GT(m.shadelStdDev, 4.0)
        << c.model << ": shadel's image is flat (luma std dev " << m.shadelStdDev << ")";
    ASSERT_TRUE(model.contains(floorKey))
        << c.model << ": no " << floorKey << " in tools/conformance/models.json (measured "
        << m.psnr << " dB; tools/conformance/compare.py --floors-from sets it)";
    double floor = model[floorKey].get<double>();
    EXPECT_GE(m.psnr, floor) << c.model << " " << modeName << ": PSNR " << m.psnr
                             << " dB against the glTF Sample Viewer, floor " << floor;
}

INSTANTIATE_TEST_SUITE_P(Models, Conformance, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& info) {
                             std::string name =
                                 info.param.model + "_" +
                                 (info.param.mode == RenderMode::Forward ? "forward" : "decoupled");
                             std::replace_if(
                                 name.begin(), name.end(),
                                 [](char ch) { return !std::isalnum(uint8_t(ch)); }, '_');
                             return name;
                         });

} // namespace
