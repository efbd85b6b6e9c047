// Golden images: the forward and decoupled renders of builtin:smooth compared with PNGs in
// tests/data/reference. Tolerance: PSNR >= 40 dB (lavapipe reproduces them exactly; the margin
// is for other drivers' rounding). After an intended change to shading, regenerate with
//   build/src/app/shadel render --scene builtin:smooth --size 128x72 --mode MODE
//       --out tests/data/reference/smooth_MODE_128x72.png
#include "gpu_test_env.h"

#include <stb/stb_image.h>

using namespace shadel;
using namespace shadel::test;

static std::vector<uint8_t> loadReference(const std::string& name, int& w, int& h) {
    std::string path = std::string(SHADEL_SOURCE_DIR) + "/tests/data/reference/" + name;
    int channels = 0;
    uint8_t* data = stbi_load(path.c_str(), &w, &h, &channels, 4);
    if (!data) return {};
    std::vector<uint8_t> out(data, data + size_t(w) * h * 4);
    stbi_image_free(data);
    return out;
}

class ReferenceImage : public ::testing::TestWithParam<RenderMode> {};

TEST_P(ReferenceImage, SmoothSceneMatchesGolden) {
    RenderMode mode = GetParam();
    std::string name = std::string("smooth_") +
                       (mode == RenderMode::Forward ? "forward" : "decoupled") + "_128x72.png";
    int w = 0, h = 0;
    std::vector<uint8_t> reference = loadReference(name, w, h);
    ASSERT_FALSE(reference.empty()) << "missing reference " << name;
    RenderOptions o;
    o.scene = "builtin:smooth";
    o.mode = mode;
    o.width = uint32_t(w);
    o.height = uint32_t(h);
    RenderRun run = renderChecked(o);
    double p = psnr(run.frames[0].rgba, reference);
    std::printf("[ figures ] %s: PSNR against golden = %.2f dB\n", name.c_str(), p);
    EXPECT_GE(p, 40.0);
}

INSTANTIATE_TEST_SUITE_P(Modes, ReferenceImage,
                         ::testing::Values(RenderMode::Forward, RenderMode::Decoupled),
                         [](const auto& info) {
                             return info.param == RenderMode::Forward ? "forward" : "decoupled";
                         });
