// Hot shader reload (rhi/shader_reload.h): editing a copy of a shader swaps the pipelines built
// from it and the frame changes; a syntax error keeps the last good pipeline and reports the
// file and line.
#include "gpu_test_env.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "render/renderer.h"
#include "rhi/shader_reload.h"
#include "scene/load.h"

using namespace shadel;
using namespace shadel::test;

namespace {

std::string readText(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

void writeText(const std::filesystem::path& p, const std::string& text) {
    std::ofstream(p, std::ios::trunc) << text;
    // A new time stamp even within the file system's clock resolution.
    std::filesystem::last_write_time(p,
                                     std::filesystem::last_write_time(p) + std::chrono::seconds(1));
}

} // namespace

TEST(ShaderReload, EditSwapsThePipelineAndABrokenShaderKeepsTheLastGoodOne) {
    namespace fs = std::filesystem;
    fs::path copy = fs::temp_directory_path() / ("shadel-reload-" + std::to_string(::getpid()));
    fs::remove_all(copy);
    fs::copy(fs::path(SHADEL_SOURCE_DIR) / "shaders", copy, fs::copy_options::recursive);

    Gpu& gpu = sharedGpu();
    enableShaderHotReload(gpu, copy.string()); // before the renderer builds its pipelines
    Scene scene = loadScene("builtin:smooth", {});
    GpuScene gs;
    uploadScene(gpu, scene, gs);
    RenderSettings settings;
    settings.width = 96;
    settings.height = 54;
    settings.timing = defaultTimingMode(gpu);
    settings.fuseTonemap = false; // the edit below is to the tonemap pass: it must run
    Renderer r;
    initRenderer(r, gpu, settings, gs);
    CameraView view = makeCameraView(findCamera(scene, ""), 96, 54);
    std::vector<uint8_t> before = renderFrame(r, gs, view).rgba;

    EXPECT_EQ(pollShaderReload(gpu).pipelinesSwapped, 0u); // nothing changed yet

    // Invert the display colour in the tonemap pass.
    fs::path tonemap = copy / "post" / "tonemap.comp";
    std::string original = readText(tonemap);
    std::string edited = original;
    size_t at = edited.find("vec3 c = linearToSrgb(");
    ASSERT_NE(at, std::string::npos);
    edited.replace(at, 22, "vec3 c = 1.0 - linearToSrgb(");
    writeText(tonemap, edited);
    ShaderReloadResult ok = pollShaderReload(gpu);
    EXPECT_TRUE(ok.errors.empty()) << (ok.errors.empty() ? "" : ok.errors[0]);
    EXPECT_EQ(ok.stagesRecompiled, std::vector<std::string>{"post/tonemap.comp"});
    EXPECT_EQ(ok.pipelinesSwapped, 1u);
    std::vector<uint8_t> inverted = renderFrame(r, gs, view).rgba;
    double changed = psnr(before, inverted);
    std::printf("[ figures ] after the edit: %.2f dB against the original frame\n", changed);
    EXPECT_LT(changed, 15.0);
    int sum = int(before[0]) + int(inverted[0]); // 1 - x on the first pixel
    EXPECT_NEAR(sum, 255, 2);

    // A syntax error on a known line: reported with file and line, the inverted pipeline stays.
    std::string broken = edited;
    size_t lineStart = broken.find("void main()");
    ASSERT_NE(lineStart, std::string::npos);
    int line = 1 + int(std::count(broken.begin(), broken.begin() + lineStart, '\n'));
    broken.insert(lineStart, "this is not glsl;\n");
    writeText(tonemap, broken);
    ShaderReloadResult bad = pollShaderReload(gpu);
    ASSERT_EQ(bad.errors.size(), 1u);
    std::printf("[ figures ] reload error: %s\n", bad.errors[0].c_str());
    EXPECT_NE(bad.errors[0].find("post/tonemap.comp:" + std::to_string(line)), std::string::npos)
        << bad.errors[0];
    EXPECT_EQ(bad.pipelinesSwapped, 0u);
    EXPECT_EQ(psnr(renderFrame(r, gs, view).rgba, inverted), 99.0);

    // Fixed again: the original frame comes back.
    writeText(tonemap, original);
    EXPECT_EQ(pollShaderReload(gpu).pipelinesSwapped, 1u);
    EXPECT_EQ(psnr(renderFrame(r, gs, view).rgba, before), 99.0);

    destroyRenderer(r);
    destroyScene(gpu, gs);
    disableShaderHotReload(gpu);
    fs::remove_all(copy);
}
