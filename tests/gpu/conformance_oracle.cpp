#include "conformance_oracle.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <stb/stb_image.h>

namespace shadel::test {
namespace fs = std::filesystem;

namespace {

const fs::path kRoot = SHADEL_SOURCE_DIR;

// The viewer writes pow(linear, 1/2.2); shadel writes the sRGB curve. The reference is decoded
// with the power and re-encoded with the sRGB curve.
uint8_t viewerToSrgb(uint8_t v) {
    double linear = std::pow(v / 255.0, 2.2);
    double s = linear <= 0.0031308 ? linear * 12.92 : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
    return uint8_t(std::lround(std::clamp(s, 0.0, 1.0) * 255.0));
}

} // namespace

const nlohmann::json& conformanceManifest() {
    static const nlohmann::json m = [] {
        std::ifstream in(kRoot / "tools/conformance/models.json");
        return in ? nlohmann::json::parse(in, nullptr, false) : nlohmann::json();
    }();
    return m;
}

nlohmann::json conformanceModel(const std::string& name) {
    const nlohmann::json& m = conformanceManifest();
    if (m.is_object() && m.contains("models"))
        for (const auto& model : m["models"])
            if (model["name"] == name) return model;
    return nullptr;
}

// (The wrapper names the sample's buffers and images by file name.)
fs::path stageConformanceModel(const nlohmann::json& model) {
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

std::vector<uint8_t> loadConformanceReference(const std::string& name, int& w, int& h) {
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

ConformanceMeasure measureAgainstReference(const std::vector<uint8_t>& ref,
                                           const std::vector<uint8_t>& img) {
    ConformanceMeasure m;
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
    o.environment = (kRoot / conformanceManifest()["environment"].get<std::string>()).string();
    o.environmentGiven = true;
    o.environmentRotationDegrees =
        conformanceManifest()["shadel_environment_rotation"].get<float>();
    o.tonemap = Tonemap::AcesNarkowicz;
    o.backgroundEnvironment = false;
    o.backgroundColor = glm::vec3(0.0f);
    o.shadows = false;
    o.addDefaultSun = false;
    // The reference is rendered at this many times the size, one sample per canvas pixel, and
    // box-filtered: shadel supersamples on the same grid, so edges and minified textures compare
    // like for like.
    o.ssaa = conformanceManifest().value("shadel_ssaa", 1u);
    return o;
}

} // namespace shadel::test
