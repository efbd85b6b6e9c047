#include "gpu_test_env.h"
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace shadel::test {

namespace {
struct SharedGpu {
    Gpu gpu;
    SharedGpu() {
        DeviceDesc d;
        d.selection = "auto";
        d.validation = true;
        createGpu(gpu, d);
    }
    ~SharedGpu() { destroyGpu(gpu); }
};
} // namespace

Gpu& sharedGpu() {
    static SharedGpu shared;
    return shared.gpu;
}

uint32_t validationErrors() {
    return sharedGpu().device.validationErrors.load();
}

RenderRun renderChecked(const RenderOptions& options) {
    Gpu& gpu = sharedGpu();
    uint32_t before = validationErrors();
    RenderOptions o = options;
    o.progress = false;
    if (o.cacheDir.empty())
        o.cacheDir = (std::filesystem::temp_directory_path() / "shadel-test-cache").string();
    RenderRun run = runRender(gpu, o);
    EXPECT_EQ(validationErrors(), before) << "validation errors while rendering " << o.scene;
    EXPECT_EQ(run.stats["shader_asserts"].get<uint64_t>(), 0u)
        << "shader asserts while rendering " << o.scene;
    return run;
}

double psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
    EXPECT_EQ(a.size(), b.size());
    double se = 0;
    size_t n = 0;
    for (size_t i = 0; i + 3 < a.size(); i += 4)
        for (int c = 0; c < 3; ++c, ++n) {
            double d = double(a[i + c]) - double(b[i + c]);
            se += d * d;
        }
    double mse = se / double(std::max<size_t>(n, 1));
    return mse == 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

RenderOptions renderOptions(const std::string& scene, RenderMode mode, uint32_t w, uint32_t h) {
    RenderOptions o;
    o.scene = scene;
    o.mode = mode;
    o.width = w;
    o.height = h;
    return o;
}

double meanFrameDelta(const RenderRun& run) {
    double sum = 0;
    size_t n = 0;
    for (size_t f = 1; f < run.frames.size(); ++f) {
        const auto& a = run.frames[f - 1].rgba;
        const auto& b = run.frames[f].rgba;
        for (size_t i = 0; i < a.size(); i += 4)
            for (int c = 0; c < 3; ++c, ++n) sum += std::abs(double(a[i + c]) - double(b[i + c]));
    }
    return sum / double(std::max<size_t>(n, 1));
}

nlohmann::json takeJsonFile(const std::string& path) {
    std::ifstream in(path);
    if (!in.good()) return nullptr;
    nlohmann::json j = nlohmann::json::parse(in);
    in.close();
    std::filesystem::remove(path);
    return j;
}

double worstFramePsnr(const RenderRun& a, const RenderRun& b) {
    double worst = 1e9;
    for (size_t i = 0; i < a.frames.size() && i < b.frames.size(); ++i)
        worst = std::min(worst, psnr(a.frames[i].rgba, b.frames[i].rgba));
    return worst;
}

std::string tempPath(const std::string& name) {
    return (std::filesystem::temp_directory_path() /
            ("shadel-test-" + std::to_string(getpid()) + "-" + name))
        .string();
}

} // namespace shadel::test
