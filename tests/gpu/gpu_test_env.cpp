#include "gpu_test_env.h"
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <glm/gtc/quaternion.hpp>

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

bool runningInCi() {
    const char* ci = std::getenv("CI");
    return ci && *ci;
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

ImageContent imageContent(const std::vector<uint8_t>& rgba) {
    size_t pixels = rgba.size() / 4, covered = 0;
    double sum = 0.0, sumSquares = 0.0;
    for (size_t i = 0; i + 3 < rgba.size(); i += 4) {
        covered += rgba[i + 3] > 0;
        for (int c = 0; c < 3; ++c) {
            double v = rgba[i + c];
            sum += v, sumSquares += v * v;
        }
    }
    ImageContent content;
    if (pixels == 0) return content;
    double n = double(pixels) * 3.0, mean = sum / n;
    content.coverage = double(covered) / double(pixels);
    content.deviation = std::sqrt(std::max(0.0, sumSquares / n - mean * mean));
    return content;
}

namespace {
// Adds a failure when neither image has content (see ImageContent).
void expectSomeContent(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
    ImageContent ca = imageContent(a), cb = imageContent(b);
    EXPECT_TRUE(ca.any() || cb.any())
        << "comparing two images without content (an empty render matches anything empty): "
        << "coverage " << ca.coverage << " and " << cb.coverage << ", RGB deviation "
        << ca.deviation << " and " << cb.deviation << " levels, " << a.size() / 4 << " and "
        << b.size() / 4 << " pixels";
}
} // namespace

double psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
    EXPECT_EQ(a.size(), b.size());
    expectSomeContent(a, b);
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
        expectSomeContent(a, b);
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

ReuseViewShares reuseViewShares(const std::vector<uint8_t>& rgba) {
    ReuseViewShares v;
    size_t covered = 0;
    for (size_t i = 0; i + 3 < rgba.size(); i += 4) {
        if (rgba[i + 3] == 0) continue; // sky
        ++covered;
        int r = rgba[i], g = rgba[i + 1], b = rgba[i + 2];
        if (r == g && g == b)
            v.carried += 1.0;
        else if (r > g + 40 && r > b + 40)
            v.notReusable += 1.0; // red
        else if (g > r + 40 && g > b + 40)
            v.fresh += 1.0; // green
        else if (b > r + 40 && b > g + 20)
            v.refresh += 1.0; // blue
        else if (r > b + 40 && g > b + 40)
            v.view += 1.0; // yellow
    }
    for (double* f : {&v.carried, &v.notReusable, &v.fresh, &v.refresh, &v.view})
        *f /= double(std::max<size_t>(covered, 1));
    return v;
}

int worstFrameErrorQuantile(const RenderRun& a, const RenderRun& b, double quantile) {
    int worst = 0;
    for (size_t f = 0; f < a.frames.size() && f < b.frames.size(); ++f) {
        const std::vector<uint8_t>& x = a.frames[f].rgba;
        const std::vector<uint8_t>& y = b.frames[f].rgba;
        EXPECT_EQ(x.size(), y.size());
        expectSomeContent(x, y);
        std::array<size_t, 256> histogram{};
        size_t n = 0;
        for (size_t i = 0; i + 3 < x.size() && i + 3 < y.size(); i += 4)
            for (int c = 0; c < 3; ++c, ++n) histogram[std::abs(int(x[i + c]) - int(y[i + c]))]++;
        size_t below = 0, rank = size_t(quantile * double(n));
        int level = 0;
        while (level < 255 && below + histogram[level] <= rank) below += histogram[level++];
        worst = std::max(worst, level);
    }
    return worst;
}

void appendBox(const float centre[3], const float half[3], std::vector<float>& positions,
               std::vector<float>& normals, std::vector<uint16_t>& indices) {
    uint16_t face = 0;
    for (int axis = 0; axis < 3; ++axis)
        for (float sign : {-1.0f, 1.0f}) {
            int u = (axis + 1) % 3, v = (axis + 2) % 3; // cross(u, v) = +axis
            for (int corner = 0; corner < 4; ++corner) {
                float p[3], n[3] = {0.0f, 0.0f, 0.0f};
                p[axis] = half[axis] * sign;
                p[u] = (corner & 1) ? half[u] : -half[u];
                p[v] = (corner & 2) ? half[v] : -half[v];
                n[axis] = sign;
                for (int k = 0; k < 3; ++k) positions.push_back(centre[k] + p[k]);
                normals.insert(normals.end(), {n[0], n[1], n[2]});
            }
            uint16_t b = uint16_t(face++ * 4);
            if (sign > 0)
                indices.insert(indices.end(), {b, uint16_t(b + 1), uint16_t(b + 3), b,
                                               uint16_t(b + 3), uint16_t(b + 2)});
            else
                indices.insert(indices.end(), {b, uint16_t(b + 3), uint16_t(b + 1), b,
                                               uint16_t(b + 2), uint16_t(b + 3)});
        }
}

std::string writeGltf(const std::string& name, nlohmann::json doc, const std::vector<float>& floats,
                      const std::vector<uint16_t>& indices) {
    std::vector<uint8_t> bin(floats.size() * 4 + indices.size() * 2);
    std::memcpy(bin.data(), floats.data(), floats.size() * 4);
    std::memcpy(bin.data() + floats.size() * 4, indices.data(), indices.size() * 2);
    std::string gltf = tempPath(name + ".gltf"), binPath = tempPath(name + ".bin");
    doc["buffers"] = {
        {{"byteLength", bin.size()}, {"uri", std::filesystem::path(binPath).filename().string()}}};
    std::ofstream(binPath, std::ios::binary)
        .write(reinterpret_cast<const char*>(bin.data()), std::streamsize(bin.size()));
    std::ofstream(gltf) << doc.dump();
    return gltf;
}

nlohmann::json gltfBufferView(size_t byteOffset, size_t byteLength) {
    return {{"buffer", 0}, {"byteOffset", byteOffset}, {"byteLength", byteLength}};
}

nlohmann::json gltfAccessor(int bufferView, int componentType, int count, const char* type) {
    return {{"bufferView", bufferView},
            {"componentType", componentType},
            {"count", count},
            {"type", type}};
}

nlohmann::json gltfRotationTowards(glm::vec3 direction) {
    glm::quat q = glm::quatLookAtRH(glm::normalize(direction), glm::vec3(0, 1, 0));
    return {q.x, q.y, q.z, q.w};
}

ReuseRuns renderReuseOnAndOff(RenderOptions o) {
    ReuseRuns r;
    o.reuse = false;
    r.off = renderChecked(o);
    o.reuse = true;
    r.on = renderChecked(o);
    return r;
}

std::string tempPath(const std::string& name) {
    return (std::filesystem::temp_directory_path() /
            ("shadel-test-" + std::to_string(getpid()) + "-" + name))
        .string();
}

} // namespace shadel::test
