// Material shading rate (render/shadel/material_rate.h): plain rough materials are shaded up to
// one MIP coarser, glossy ones and anything a light with sharp edges reaches keep the full rate,
// and the image stays as close to the supersampled reference as at the full rate.
#include "gpu_test_env.h"

#include <cmath>
#include <limits>

#include "render/shadel/material_rate.h"
#include "render/shadel/texture_rate.h"
#include "scene/scene.h"

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

// Texture-limited rate (render/shadel/texture_rate.h): textureLod is the finest whole level whose
// shadels are at most half a texel of the material's densest texture apart; the rate coarsens a
// sample no further than the level before it (a quarter texel).
TEST(MaterialRate, TexturedMaterialsStopAtAQuarterTexel) {
    // A quad: material UVs and shadel UVs both span [0,1]^2, 64x64 MIP-0 shadels.
    std::vector<glm::vec2> uv = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    std::vector<uint32_t> quad = {0, 1, 2, 0, 2, 3};
    float uvPerShadel = uvPerShadelLog2(uv, uv, quad, {64, 64});
    EXPECT_NEAR(uvPerShadel, -6.0f, 1e-5f);
    // 16x16 texels: a texel is 4 MIP-0 shadels, half a texel is level 1.
    EXPECT_FLOAT_EQ(textureLod(uvPerShadel, 4.0f, 2.0f), 1.0f);
    // 256x256: a texel is a quarter shadel; 24x24 (log2 4.585): rounded to the finer level.
    EXPECT_FLOAT_EQ(textureLod(uvPerShadel, 8.0f, 2.0f), -3.0f);
    EXPECT_FLOAT_EQ(textureLod(uvPerShadel, std::log2(24.0f), 2.0f), 0.0f);
    // UVs that do not vary: no texture detail, no limit.
    std::vector<glm::vec2> flat(4, glm::vec2(0.5f));
    EXPECT_EQ(textureLod(uvPerShadelLog2(flat, uv, quad, {64, 64}), 8.0f, 2.0f),
              float(SHADEL_TEXTURE_LOD_NONE));
    // The mapping's dense end counts: one triangle holding 4x the UV area per shadel (2x per
    // axis) and 11% of the surface sets the density; at 2% it would not.
    std::vector<glm::vec2> shadelUv = {{0, 0}, {1, 0},    {1, 1},   {0, 1},
                                       {0, 0}, {0.5f, 0}, {0, 0.5f}};
    std::vector<glm::vec2> dense = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}, {1, 0}, {0, 1}};
    std::vector<uint32_t> tris = {0, 1, 2, 0, 2, 3, 4, 5, 6};
    EXPECT_NEAR(uvPerShadelLog2(dense, shadelUv, tris, {64, 64}), -5.0f, 1e-5f);
    shadelUv[5] = {0.2f, 0}, shadelUv[6] = {0, 0.2f};
    dense[5] = {0.4f, 0}, dense[6] = {0, 0.4f};
    EXPECT_NEAR(uvPerShadelLog2(dense, shadelUv, tris, {64, 64}), -6.0f, 1e-5f);

    // The rate stops a level before the texture's unless the sample is already coarser.
    EXPECT_FLOAT_EQ(materialRateLod(-2.0f, 1.0f, 1.0f), -1.0f);
    EXPECT_FLOAT_EQ(materialRateLod(-0.5f, 1.0f, 1.0f), 0.0f);
    EXPECT_FLOAT_EQ(materialRateLod(0.5f, 1.0f, 1.0f), 0.5f);
    EXPECT_FLOAT_EQ(materialRateLod(1.5f, 1.0f, 1.0f), 1.5f);
    EXPECT_FLOAT_EQ(materialRateLod(0.5f, 1.0f, SHADEL_TEXTURE_LOD_NONE), 1.5f);
    // Textures alone allow the bias; procedurals, clear coat and sheen do not.
    MaterialRate rate;
    EXPECT_FLOAT_EQ(materialRateBias(rate, MATERIAL_FEATURE_TEXTURES, 1.0f), rate.maxBias);
    EXPECT_EQ(materialRateBias(rate, MATERIAL_FEATURE_TEXTURES | MATERIAL_FEATURE_CLEARCOAT, 1.0f),
              0.0f);
}

// A material's texels: its densest texture with KHR_texture_transform's scale, and how glossy its
// metallic-roughness texture can make it.
TEST(MaterialRate, MaterialTexelsTakeTheDensestTextureAndTheGlossiestTexel) {
    Scene scene;
    Texture small, large;
    small.width = small.height = 64;
    small.rgba8.assign(64 * 64 * 4, 255);
    large.width = large.height = 256;
    large.rgba8.assign(256 * 256 * 4, 200);
    for (int i = 0; i < 256 * 256 / 10; ++i) large.rgba8[size_t(i) * 4 + 1] = 51; // 10%: G 0.2
    scene.textures = {small, large};
    Material m;
    m.baseColorTexture = 0;
    m.uvTransforms[uint32_t(TextureSlot::BaseColor)].c0 = {8.0f, 0.0f}; // 8x8 repeats: 512/uv
    m.uvTransforms[uint32_t(TextureSlot::BaseColor)].c1 = {0.0f, 8.0f};
    m.metallicRoughnessTexture = 1;
    scene.materials = {m};
    std::vector<MaterialTexels> t = materialTexels(scene);
    ASSERT_EQ(t.size(), 1u);
    EXPECT_TRUE(t[0].known);
    EXPECT_NEAR(t[0].texelsPerUvLog2, 9.0f, 1e-5f); // the repeated 64^2 beats the 256^2
    EXPECT_NEAR(t[0].roughnessScale, 51.0f / 255.0f, 1e-6f);
    scene.materials[0].metallicRoughnessTexture = 7; // out of range: unknown
    EXPECT_FALSE(materialTexels(scene)[0].known);
}

// assimp's BoxTextured: a 211x211 texture on each face of a rough box. At 1280x720 the view
// magnifies it: the texture-limited rate reads one level where two were blended and shades it
// under 2 shadels per covered pixel, and the image stays that of the full rate. At 320x180 the
// texture is minified: nothing changes.
TEST(MaterialRate, MagnifiedTexturesAreShadedCoarser) {
    const std::string box =
        "/usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb";
    RenderOptions o = renderOptions(box, RenderMode::Decoupled, 1280, 720);
    o.frames = 2;
    RenderRun on = renderChecked(o);
    o.materialRate = false;
    RenderRun off = renderChecked(o);
    double sppOn = statNumber(on, "shadels_per_pixel"),
           sppOff = statNumber(off, "shadels_per_pixel");
    double p = psnr(on.frames.back().rgba, off.frames.back().rgba);
    std::printf("[ figures ] BoxTextured 1280x720: shadels per pixel %.3f (rate off %.3f), on vs "
                "off %.2f dB\n",
                sppOn, sppOff, p);
    EXPECT_EQ(on.stats["objects_rate_textured"].get<uint64_t>(), 1u);
    EXPECT_LT(sppOn, 0.75 * sppOff);
    EXPECT_LE(sppOn, 2.0);
    EXPECT_GE(p, 50.0);
    EXPECT_EQ(on.stats["reconstruction_misses"].get<uint64_t>(), 0u);

    RenderOptions small = renderOptions(box, RenderMode::Decoupled, 320, 180);
    RenderRun smallOn = renderChecked(small);
    small.materialRate = false;
    RenderRun smallOff = renderChecked(small);
    EXPECT_EQ(smallOn.stats["objects_rate_textured"].get<uint64_t>(), 1u);
    EXPECT_TRUE(smallOn.frames[0].rgba == smallOff.frames[0].rgba)
        << "a minified texture lost detail";
}
