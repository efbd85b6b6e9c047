// Material shading rate (render/shadel/material_rate.h): plain rough materials are shaded up to
// one MIP coarser, glossy ones and anything a light with sharp edges reaches keep the full rate,
// and the image stays as close to the supersampled reference as at the full rate.
#include "gpu_test_env.h"

#include <cmath>
#include <limits>

#include "render/shadel/material_rate.h"

using namespace shadel;
using namespace shadel::test;

TEST(MaterialRate, BiasFollowsRoughnessForPlainMaterialsOnly) {
    MaterialRate rate;
    EXPECT_EQ(materialRateBias(rate, 0u, 0.1f), 0.0f);
    EXPECT_EQ(materialRateBias(rate, 0u, rate.sharpRoughness), 0.0f);
    EXPECT_FLOAT_EQ(materialRateBias(rate, 0u, rate.broadRoughness), rate.maxBias);
    EXPECT_FLOAT_EQ(materialRateBias(rate, 0u, 1.0f), rate.maxBias);
    float mid = materialRateBias(rate, 0u, 0.5f * (rate.sharpRoughness + rate.broadRoughness));
    EXPECT_NEAR(mid, 0.5f * rate.maxBias, 1e-5f);
    // Any material feature (textures, procedurals, clear coat, sheen): its pattern is the signal.
    EXPECT_EQ(materialRateBias(rate, MATERIAL_FEATURE_PROCEDURAL, 1.0f), 0.0f);
    EXPECT_EQ(materialRateBias(rate, MATERIAL_FEATURES_ALL, 1.0f), 0.0f);
    EXPECT_EQ(materialRateBias(rate, 0u, std::numeric_limits<float>::quiet_NaN()), 0.0f);
}

// The rate coarsens a sample up to SHADEL_MATERIAL_RATE_MAX_LOD (3), never past it, and leaves
// coarser samples alone.
TEST(MaterialRate, LodIsBoundedWhereChartGuttersBleed) {
    EXPECT_FLOAT_EQ(materialRateLod(0.5f, 1.0f), 1.5f);
    EXPECT_FLOAT_EQ(materialRateLod(2.5f, 1.0f), 3.0f);
    EXPECT_FLOAT_EQ(materialRateLod(3.5f, 1.0f), 3.5f);
    EXPECT_FLOAT_EQ(materialRateLod(-2.0f, 1.0f), -1.0f);
    EXPECT_FLOAT_EQ(materialRateLod(1.25f, 0.0f), 1.25f);
    // The default bound lies past the bake's clean levels (2^k <= gutter), not inside them.
    EXPECT_GT(SHADEL_MATERIAL_RATE_MAX_LOD, 1.0);
}

TEST(MaterialRate, SharpLightsAreFoundNearTheBox) {
    gpu::GpuLight omni{};
    omni.type = LIGHT_POINT;
    omni.range = 2.0f;
    omni.shadowIndex = LIGHT_NO_SHADOW;
    EXPECT_FALSE(lightDrawsSharpEdges(omni));
    gpu::GpuLight gobo = omni;
    gobo.flags = LIGHT_FLAG_PROJECTED;
    EXPECT_TRUE(lightDrawsSharpEdges(gobo));
    gpu::GpuLight shadowed = omni;
    shadowed.shadowIndex = 0;
    EXPECT_TRUE(lightDrawsSharpEdges(shadowed));
    gpu::GpuLight blocked = omni;
    blocked.blockerCount = 1;
    EXPECT_TRUE(lightDrawsSharpEdges(blocked));

    SharpLights sharp;
    std::vector<gpu::GpuLight> lights;
    for (int i = 0; i < 100; ++i) { // a row of smooth lights, one gobo at x = 50
        gpu::GpuLight l = i == 50 ? gobo : omni;
        l.position = glm::vec3(float(i), 0.0f, 0.0f);
        lights.push_back(l);
    }
    updateSharpLights(sharp, lights, false, false, {}); // the first call builds
    EXPECT_EQ(sharp.spheres.size(), 1u);
    EXPECT_TRUE(
        sharpLightReaches(sharp, glm::vec3(49.0f, -1.0f, -1.0f), glm::vec3(49.5f, 1.0f, 1.0f)));
    EXPECT_FALSE(
        sharpLightReaches(sharp, glm::vec3(10.0f, -1.0f, -1.0f), glm::vec3(12.0f, 1.0f, 1.0f)));
    EXPECT_FALSE(
        sharpLightReaches(sharp, glm::vec3(50.0f, 5.0f, 0.0f), glm::vec3(51.0f, 6.0f, 1.0f)));
    uint32_t version = sharp.version;
    updateSharpLights(sharp, lights, false, false, {}); // unchanged: kept
    EXPECT_EQ(sharp.version, version);
    lights[50].position.y = 10.0f;
    updateSharpLights(sharp, lights, true, false, {});
    EXPECT_NE(sharp.version, version);
    EXPECT_TRUE(
        sharpLightReaches(sharp, glm::vec3(50.0f, 9.0f, 0.0f), glm::vec3(51.0f, 9.5f, 1.0f)));
}

namespace {
double statNumber(const RenderRun& run, const char* name) {
    return run.stats[name].get<double>();
}
} // namespace

// builtin:default is mostly plain rough materials lit by the sun: they are shaded coarser, and
// the image stays as close to an 4x4 supersampled forward reference as at the full rate (at the
// size of the bench, where the shading rate shows).
TEST(MaterialRate, ShadesPlainRoughMaterialsCoarserAtTheSameQuality) {
    RenderOptions ref = renderOptions("builtin:default", RenderMode::Forward, 640, 360);
    ref.ssaa = 4;
    RenderRun reference = renderChecked(ref);
    RenderOptions o = renderOptions("builtin:default", RenderMode::Decoupled, 640, 360);
    o.frames = 2;
    RenderRun on = renderChecked(o);
    o.materialRate = false;
    RenderRun off = renderChecked(o);
    RenderRun fwd = renderChecked(renderOptions("builtin:default", RenderMode::Forward, 640, 360));
    double pOn = psnr(on.frames.back().rgba, reference.frames[0].rgba);
    double pOff = psnr(off.frames.back().rgba, reference.frames[0].rgba);
    double pFwd = psnr(fwd.frames[0].rgba, reference.frames[0].rgba);
    double sppOn = statNumber(on, "shadels_per_pixel"),
           sppOff = statNumber(off, "shadels_per_pixel");
    std::printf(
        "[ figures ] default 640x360 vs 4x4 SSAA: material rate on %.2f dB (%.3f shadels per "
        "pixel, %llu objects biased), off %.2f dB (%.3f), forward %.2f dB\n",
        pOn, sppOn, (unsigned long long)on.stats["objects_rate_biased"].get<uint64_t>(), pOff,
        sppOff, pFwd);
    EXPECT_GT(on.stats["objects_rate_biased"].get<uint64_t>(), 0u);
    EXPECT_EQ(off.stats["objects_rate_biased"].get<uint64_t>(), 0u);
    EXPECT_LT(sppOn, 0.75 * sppOff);
    EXPECT_GE(pOn, pOff - 0.25);
    EXPECT_GE(pOn, pFwd + 3.0);
    EXPECT_GE(psnr(on.frames.back().rgba, off.frames.back().rgba), 40.0);
    EXPECT_EQ(on.stats["reconstruction_misses"].get<uint64_t>(), 0u);
}

// builtin:blockers' room is lit by a light its walls block: blockers draw sharp edges, so what
// that light reaches keeps the full rate and the image does not change.
TEST(MaterialRate, LightsWithSharpEdgesKeepTheFullRate) {
    RenderOptions o = renderOptions("builtin:blockers", RenderMode::Decoupled, 320, 180);
    RenderRun on = renderChecked(o);
    o.materialRate = false;
    RenderRun off = renderChecked(o);
    uint64_t biased = on.stats["objects_rate_biased"].get<uint64_t>();
    uint64_t decoupled = on.stats["objects_decoupled"].get<uint64_t>();
    double p = psnr(on.frames[0].rgba, off.frames[0].rgba);
    std::printf("[ figures ] blockers 320x180: %llu of %llu objects biased, on vs off %.2f dB\n",
                (unsigned long long)biased, (unsigned long long)decoupled, p);
    EXPECT_LT(biased, decoupled);
    EXPECT_EQ(biased, 0u); // the blocked light reaches the whole room
    EXPECT_GE(p, 50.0);
}

// An object at the full rate bias reads one MIP level (shadelLevels narrows the blend band with
// the bias): tests/data/gltf/quad.glb's quad is plain grey at roughness 0.7 (a full MIP) and seen
// at a slant, so its samples span LOD fractions. With the rate on, the band setting changes
// nothing; with it off, the wider band reads two levels over more of the quad.
TEST(MaterialRate, FullyBiasedObjectsReadOneLevel) {
    RenderOptions o = renderOptions(std::string(SHADEL_SOURCE_DIR) + "/tests/data/gltf/quad.glb",
                                    RenderMode::Decoupled, 320, 180);
    o.trilinearBand = 1.0f;
    RenderRun wide = renderChecked(o);
    o.trilinearBand = 0.0f;
    RenderRun one = renderChecked(o);
    EXPECT_EQ(wide.stats["objects_rate_biased"].get<uint64_t>(), 1u);
    EXPECT_DOUBLE_EQ(statNumber(wide, "material_rate_bias_mean"), 1.0);
    EXPECT_EQ(wide.stats["chunks_allocated"], one.stats["chunks_allocated"]);
    EXPECT_TRUE(wide.frames[0].rgba == one.frames[0].rgba) << "the band changed the image";

    o.materialRate = false;
    o.trilinearBand = 1.0f;
    RenderRun offWide = renderChecked(o);
    o.trilinearBand = 0.0f;
    RenderRun offOne = renderChecked(o);
    std::printf("[ figures ] quad.glb 320x180 chunks, band 1 / band 0: rate on %llu / %llu, rate "
                "off %llu / %llu\n",
                (unsigned long long)wide.stats["chunks_allocated"].get<uint64_t>(),
                (unsigned long long)one.stats["chunks_allocated"].get<uint64_t>(),
                (unsigned long long)offWide.stats["chunks_allocated"].get<uint64_t>(),
                (unsigned long long)offOne.stats["chunks_allocated"].get<uint64_t>());
    EXPECT_GT(offWide.stats["chunks_allocated"].get<uint64_t>(),
              offOne.stats["chunks_allocated"].get<uint64_t>());
    EXPECT_EQ(wide.stats["reconstruction_misses"].get<uint64_t>(), 0u);
    EXPECT_EQ(offWide.stats["reconstruction_misses"].get<uint64_t>(), 0u);
}
