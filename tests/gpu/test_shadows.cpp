// Shadows: spot shadow maps share one atlas placed by the block allocator;
// a shadow only removes light; PCSS (soft spots, --sun-shadows pcss) changes penumbrae, not the
// lit and shadowed areas as a whole.
#include "gpu_test_env.h"

#include <algorithm>
#include <cmath>

using namespace shadel;
using namespace shadel::test;

namespace {

double meanGreen(const std::vector<uint8_t>& px) {
    double sum = 0;
    for (size_t i = 0; i < px.size(); i += 4) sum += px[i + 1];
    return sum / double(px.size() / 4);
}

} // namespace

TEST(Shadows, SpotShadowMapsOnlyRemoveLight) {
    RenderOptions o = renderOptions("builtin:lights", RenderMode::Forward, 192, 108);
    RenderRun on = renderChecked(o);
    o.spotShadows = false;
    RenderRun off = renderChecked(o);
    EXPECT_EQ(on.stats["spot_shadow_maps"].get<uint64_t>(), 16u);
    EXPECT_EQ(on.stats["spot_shadow_maps_unplaced"].get<uint64_t>(), 0u);
    // 8 soft maps of 1024^2 and 8 of 512^2 fill 5/8 of the 4096^2 atlas.
    EXPECT_NEAR(on.stats["spot_shadow_atlas_fill"].get<double>(), 0.625, 1e-6);
    const auto& a = on.frames[0].rgba;
    const auto& b = off.frames[0].rgba;
    size_t darker = 0, brighter = 0;
    for (size_t i = 0; i < a.size(); i += 4) {
        int d = 0;
        for (int c = 0; c < 3; ++c) d = std::max(d, int(b[i + c]) - int(a[i + c]));
        int u = 0;
        for (int c = 0; c < 3; ++c) u = std::max(u, int(a[i + c]) - int(b[i + c]));
        darker += d > 8;
        brighter += u > 2;
    }
    EXPECT_GT(darker, 50u) << "the shadowed spots cast visible shadows";
    EXPECT_EQ(brighter, 0u) << "a shadow never adds light";
}

TEST(Shadows, SunPcssSoftensEdgesButKeepsTheLighting) {
    RenderOptions o = renderOptions("builtin:default", RenderMode::Forward, 192, 108);
    RenderRun pcf = renderChecked(o);
    o.sunSoftShadows = true;
    RenderRun pcss = renderChecked(o);
    EXPECT_EQ(pcss.stats["sun_shadows"].get<std::string>(), "pcss");
    double p = psnr(pcf.frames[0].rgba, pcss.frames[0].rgba);
    EXPECT_LT(p, 60.0) << "PCSS changes the penumbrae";
    EXPECT_GT(p, 25.0) << "but not the image as a whole";
    EXPECT_NEAR(meanGreen(pcf.frames[0].rgba), meanGreen(pcss.frames[0].rgba), 3.0);
}
