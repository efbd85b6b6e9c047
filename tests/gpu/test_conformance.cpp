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
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>
#include <stb/stb_image.h>

#include "gpu_test_env.h"

using namespace shadel;
using namespace shadel::test;
namespace fs = std::filesystem;

namespace {

const fs::path kRoot = SHADEL_SOURCE_DIR;

const nlohmann::json& manifest() {
    static const nlohmann::json m = [] {
        std::ifstream in(kRoot / "tools/conformance/models.json");
        return in ? nlohmann::json::parse(in, nullptr, false) : nlohmann::json();
    }();
    return m;
}

struct Case {
    std::string model;
    RenderMode mode;
};
void PrintTo(const Case& c, std::ostream* os) {
    *os << c.model << (c.mode == RenderMode::Forward ? " forward" : " decoupled");
}

std::vector<Case> cases() {
    std::vector<Case> out;
    const nlohmann::json& m = manifest();
    if (!m.is_object() || !m.contains("models")) return out;
    for (const auto& model : m["models"])
        for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled})
            out.push_back({model["name"].get<std::string>(), mode});
    return out;
}

// The model's own folder and, for wrappers of sample models, its resources folder, linked into
// one scratch folder (the wrapper names the sample's buffers and images by file name).
fs::path stage(const nlohmann::json& model) {
    fs::path dir = tempPath("conformance_" + model["name"].get<std::string>());
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::vector<fs::path> sources;
    if (model.contains("resources")) sources.push_back(model["resources"].get<std::string>());
    sources.push_back((kRoot / model["file"].get<std::string>()).parent_path());
    for (const fs::path& src : sources)
        for (const auto& entry : fs::directory_iterator(src)) {
            fs::path dst = dir / entry.path().filename();
            if (fs::exists(fs::symlink_status(dst))) fs::remove(dst);
            fs::create_symlink(entry.path(), dst);
        }
    return dir / fs::path(model["file"].get<std::string>()).filename();
}

// The viewer writes pow(linear, 1/2.2); shadel writes the sRGB curve. The reference is decoded
// with the power and re-encoded with the sRGB curve.
uint8_t viewerToSrgb(uint8_t v) {
    double linear = std::pow(v / 255.0, 2.2);
    double s = linear <= 0.0031308 ? linear * 12.92 : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
    return uint8_t(std::lround(std::clamp(s, 0.0, 1.0) * 255.0));
}

// shadel's supersampled PNG has straight alpha (the covered samples' colour, alpha their share);
// the reference holds partly covered pixels composited over black as light. This puts shadel's
// in the same form.
void compositeOverBlack(std::vector<uint8_t>& rgba) {
    for (size_t i = 0; i + 3 < rgba.size(); i += 4) {
        uint8_t a = rgba[i + 3];
        if (a == 0 || a == 255) continue;
        for (int c = 0; c < 3; ++c) {
            double e = rgba[i + c] / 255.0;
            double linear =
                (e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4)) * (a / 255.0);
            double s =
                linear <= 0.0031308 ? linear * 12.92 : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
            rgba[i + c] = uint8_t(std::lround(std::clamp(s, 0.0, 1.0) * 255.0));
        }
    }
}

std::vector<uint8_t> loadReference(const std::string& name, int& w, int& h) {
    fs::path path = kRoot / "tests/data/conformance/reference" / (name + ".png");
    int channels = 0;
    uint8_t* data = stbi_load(path.string().c_str(), &w, &h, &channels, 4);
    if (!data) return {};
    std::vector<uint8_t> out(data, data + size_t(w) * h * 4);
    stbi_image_free(data);
    for (size_t i = 0; i < out.size(); i += 4)
        for (int c = 0; c < 3; ++c) out[i + c] = viewerToSrgb(out[i + c]);
    return out;
}

struct Measure {
    double psnr = 0.0;
    size_t covered = 0;        // pixels either image covers
    size_t shadelCovered = 0;  // pixels shadel covers
    double shadelStdDev = 0.0; // of shadel's luma over its covered pixels (8-bit levels)
};

Measure measure(const std::vector<uint8_t>& ref, const std::vector<uint8_t>& img) {
    Measure m;
    double se = 0.0, sum = 0.0, sum2 = 0.0;
    for (size_t i = 0; i + 3 < img.size(); i += 4) {
        bool shadel = img[i + 3] > 0;
        if (shadel) {
            double y = 0.2126 * img[i] + 0.7152 * img[i + 1] + 0.0722 * img[i + 2];
            sum += y;
            sum2 += y * y;
            ++m.shadelCovered;
        }
        if (!shadel && ref[i + 3] == 0) continue;
        ++m.covered;
        for (int c = 0; c < 3; ++c) {
            double d = double(ref[i + c]) - double(img[i + c]);
            se += d * d;
        }
    }
    if (m.shadelCovered > 0) {
        double mean = sum / double(m.shadelCovered);
        m.shadelStdDev = std::sqrt(std::max(0.0, sum2 / double(m.shadelCovered) - mean * mean));
    }
    double mse = se / double(std::max<size_t>(m.covered * 3, 1));
    m.psnr = mse == 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
    return m;
}

// The reference's view: camera and light from the file, the manifest's environment (the
// viewer's rotation 90 is shadel's 0), ACES (Narkowicz) at exposure 0 EV, no shadows (the
// reference draws none), no added sun, a black background with alpha 0 (coverage).
RenderOptions conformanceOptions(const std::string& scene, RenderMode mode, uint32_t w,
                                 uint32_t h) {
    RenderOptions o = renderOptions(scene, mode, w, h);
    o.camera = "conformance";
    o.allowExternalFiles = true;
    o.exposure = 1.0f;
    o.environment = (kRoot / manifest()["environment"].get<std::string>()).string();
    o.environmentGiven = true;
    o.environmentRotationDegrees = manifest()["shadel_environment_rotation"].get<float>();
    o.tonemap = Tonemap::AcesNarkowicz;
    o.backgroundEnvironment = false;
    o.backgroundColor = glm::vec3(0.0f);
    o.shadows = false;
    o.addDefaultSun = false;
    // The reference is rendered at this many times the size, one sample per canvas pixel, and
    // box-filtered: shadel supersamples on the same grid, so edges and minified textures compare
    // like for like.
    o.ssaa = manifest().value("shadel_ssaa", 1u);
    return o;
}

class Conformance : public ::testing::TestWithParam<Case> {};

TEST_P(Conformance, MatchesSampleViewer) {
    const Case& c = GetParam();
    nlohmann::json model;
    for (const auto& m : manifest()["models"])
        if (m["name"] == c.model) model = m;
    SHADEL_REQUIRE(!model.contains("resources") ||
                       fs::exists(model["resources"].get<std::string>()),
                   model["resources"].get<std::string>() << " (the assimp-testmodels package)");
    const char* modeName = c.mode == RenderMode::Forward ? "forward" : "decoupled";
    std::string floorKey = std::string("floor_") + modeName;

    int w = 0, h = 0;
    std::vector<uint8_t> ref = loadReference(c.model, w, h);
    ASSERT_FALSE(ref.empty()) << "missing reference " << c.model << ".png";
    ASSERT_EQ(uint32_t(w), manifest()["size"][0].get<uint32_t>());
    ASSERT_EQ(uint32_t(h), manifest()["size"][1].get<uint32_t>());

    fs::path scene = stage(model);
    RenderRun run = renderChecked(conformanceOptions(scene.string(), c.mode, w, h));
    ASSERT_EQ(run.frames.size(), 1u);
    std::vector<uint8_t> img = run.frames[0].rgba;
    compositeOverBlack(img);
    ASSERT_EQ(img.size(), ref.size());
    fs::remove_all(scene.parent_path());

    Measure m = measure(ref, img);
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
