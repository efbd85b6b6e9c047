// Distance-field lighting applied by the shared shading code (shaders/common/lighting.glsl,
// render/distance_fields): far-field sun shadows and AO on the ambient, per pixel (forward) and
// per shadel (decoupled).
#include <cstdio>

#include "gpu_test_env.h"

using namespace shadel;
using namespace shadel::test;

namespace {

RenderOptions withFields(const char* scene, RenderMode mode, float shadowStart, uint32_t w,
                         uint32_t h) {
    RenderOptions o = renderOptions(scene, mode, w, h);
    o.screenSpace = true;
    o.distanceFields = true;
    o.dfShadowStart = shadowStart;
    o.progress = false;
    return o;
}

} // namespace

// The image lit with the distance-field sun shadow everywhere (--df-shadow-start 0) against the
// same image shadow-mapped everywhere (a start beyond the scene): where both exist (every pixel
// of builtin:smooth: its shadow map covers the scene) they agree; only the shadow term differs.
TEST(DistanceFields, AppliedShadowsAgreeWithTheShadowMap) {
    RenderRun traced =
        renderChecked(withFields("builtin:smooth", RenderMode::Forward, 0.0f, 320, 180));
    RenderRun mapped =
        renderChecked(withFields("builtin:smooth", RenderMode::Forward, 1e6f, 320, 180));
    double p = psnr(traced.frames[0].rgba, mapped.frames[0].rgba);
    std::printf("smooth 320x180: image with DF shadows vs shadow-mapped %.2f dB\n", p);
    EXPECT_GE(p, 30.0);
    EXPECT_LT(p, 99.0); // the fields were applied: the images are not identical
}

// The shadel path traces the same fields per shadel through the same shadeSurface: decoupled
// matches forward on the arena (DF shadows everywhere, AO), with no reconstruction misses.
TEST(DistanceFields, DecoupledMatchesForward) {
    RenderRun forward =
        renderChecked(withFields("builtin:arena", RenderMode::Forward, 0.0f, 192, 108));
    RenderRun decoupled =
        renderChecked(withFields("builtin:arena", RenderMode::Decoupled, 0.0f, 192, 108));
    double p = psnr(forward.frames[0].rgba, decoupled.frames[0].rgba);
    std::printf("arena 192x108 with DF lighting: decoupled vs forward %.2f dB, %llu misses\n", p,
                (unsigned long long)decoupled.stats["reconstruction_misses"].get<uint64_t>());
    EXPECT_GE(p, 30.0);
    EXPECT_EQ(decoupled.stats["reconstruction_misses"].get<uint64_t>(), 0u);
    // And the fields change the decoupled image (AO, far shadows) against no fields.
    RenderOptions plain = withFields("builtin:arena", RenderMode::Decoupled, 0.0f, 192, 108);
    plain.distanceFields = false;
    RenderRun without = renderChecked(plain);
    EXPECT_LT(psnr(decoupled.frames[0].rgba, without.frames[0].rgba), 60.0);
}
