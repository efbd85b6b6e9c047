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
    o.distanceFieldLighting = true;
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
    plain.distanceFieldLighting = false;
    RenderRun without = renderChecked(plain);
    EXPECT_LT(psnr(decoupled.frames[0].rgba, without.frames[0].rgba), 60.0);
}

// Residency (--df-residency): only the fields of meshes near the camera are in the 3-D atlas,
// streamed in and out as the camera orbits, their room reused, and the atlas never overlaps.
// Within 30 m the arena's view is lit as with every field resident; within 1 m most fields are
// missing and the image shows it (the residency is what the shader reads).
TEST(DistanceFields, ResidencyStreamsFieldsAsTheCameraMoves) {
    auto orbit = [](float residency) {
        RenderOptions o = withFields("builtin:arena", RenderMode::Forward, 0.0f, 192, 108);
        o.frames = 12;
        o.cameraPath = CameraPath::Orbit;
        o.dfResidencyDistance = residency;
        return renderChecked(o);
    };
    RenderRun all = orbit(0.0f), near = orbit(30.0f), tiny = orbit(1.0f);
    const auto& a = all.stats["distance_fields"];
    const auto& n = near.stats["distance_fields"];
    double same = psnr(near.frames.back().rgba, all.frames.back().rgba);
    double missing = psnr(tiny.frames.back().rgba, all.frames.back().rgba);
    std::printf("[ figures ] arena 192x108 orbit, 12 frames: %u of %u fields resident within 30 m "
                "(%llu streamed in, %llu evicted), last frame vs all resident %.2f dB; within 1 m "
                "%u resident, %.2f dB\n",
                n["meshes_in_atlas"].get<uint32_t>(), a["meshes_in_atlas"].get<uint32_t>(),
                (unsigned long long)n["streamed_in"].get<uint64_t>(),
                (unsigned long long)n["evicted"].get<uint64_t>(), same,
                tiny.stats["distance_fields"]["meshes_in_atlas"].get<uint32_t>(), missing);
    EXPECT_EQ(a["streamed_in"].get<uint64_t>(), 0u); // placed at load
    EXPECT_LT(n["meshes_in_atlas"].get<uint32_t>(), a["meshes_in_atlas"].get<uint32_t>());
    EXPECT_GT(n["streamed_in"].get<uint64_t>(), n["meshes_in_atlas"].get<uint64_t>()); // churn
    EXPECT_GT(n["evicted"].get<uint64_t>(), 0u);
    EXPECT_TRUE(n["atlas_valid"].get<bool>());
    EXPECT_GE(same, 50.0);
    EXPECT_LT(missing, 45.0);
}

// A field that comes into the atlas or leaves it adds or takes away its DF shadow and occlusion:
// decoupled reuse must not carry over the shading it changed (reuse_invalidation.h). Every
// frame with reuse matches the frame shaded from scratch as closely as it does when every field
// stays resident (reuse carries view-dependent terms within a tolerance, chunkViewTurned);
// carried over, frame 3 fell to 49 dB.
TEST(DistanceFields, ResidencyChangesAreNotCarriedOverByReuse) {
    RenderOptions o = withFields("builtin:arena", RenderMode::Decoupled, 0.0f, 192, 108);
    o.frames = 12;
    o.cameraPath = CameraPath::Orbit;
    auto [residentOn, residentOff] = renderReuseOnAndOff(o); // every field resident
    double resident = worstFramePsnr(residentOn, residentOff);
    o.dfResidencyDistance = 8.0f;
    auto [on, off] = renderReuseOnAndOff(o);
    double worst = worstFramePsnr(on, off);
    const auto& df = on.stats["distance_fields"];
    std::printf("[ figures ] arena 192x108 orbit, --df-residency 8: %llu streamed in, %llu "
                "evicted; reuse on vs off worst frame %.2f dB (every field resident: %.2f dB), "
                "reuse fraction %.3f\n",
                (unsigned long long)df["streamed_in"].get<uint64_t>(),
                (unsigned long long)df["evicted"].get<uint64_t>(), worst, resident,
                on.stats["reuse_fraction"].get<double>());
    EXPECT_GT(df["evicted"].get<uint64_t>(), 0u);
    EXPECT_GE(worst, resident - 1.0);
    EXPECT_GE(worst, 52.0);
    EXPECT_GT(on.stats["reuse_fraction"].get<double>(), 0.2);
}
