// Image-based lighting (render/environment, shaders/common/environment_lighting.glsl) judged
// against analytic cases and the sky it reflects:
// - the furnace: in a uniform environment of radiance L, a white surface reflects L whatever its
//   metalness and roughness (energy conserved, multiple scattering included); the background is
//   L too;
// - a mirror sphere under the built-in sky reflects the sky (its mean luminance against the
//   sky's above the horizon);
// - decoupled reuse: an environment turning every frame leaves no stale shading.
#include "gpu_test_env.h"
#include "scene_files.h"

#include <cmath>
#include <cstdio>
#include <fstream>

#include <stb/stb_image.h>

using namespace shadel;
using namespace shadel::test;
using nlohmann::json;

namespace {

constexpr float kPi = 3.14159265358979f;

// A UV sphere of radius 1 at the origin, the given material, a camera on +Z looking at it.
std::string writeSphere(const std::string& name, float metallic, float roughness,
                        glm::vec3 baseColor) {
    const int rings = 24, segments = 48;
    std::vector<float> positions, normals;
    std::vector<uint16_t> indices;
    for (int r = 0; r <= rings; ++r)
        for (int s = 0; s <= segments; ++s) {
            float theta = kPi * float(r) / rings, phi = 2.0f * kPi * float(s) / segments;
            glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta),
                        std::sin(theta) * std::sin(phi));
            positions.insert(positions.end(), {n.x, n.y, n.z});
            normals.insert(normals.end(), {n.x, n.y, n.z});
        }
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            uint16_t a = uint16_t(r * (segments + 1) + s), b = uint16_t(a + segments + 1);
            indices.insert(indices.end(),
                           {a, uint16_t(a + 1), b, uint16_t(a + 1), uint16_t(b + 1), b});
        }
    size_t count = positions.size() / 3;
    std::vector<float> floats = positions;
    floats.insert(floats.end(), normals.begin(), normals.end());
    json doc;
    doc["asset"] = {{"version", "2.0"}};
    doc["scene"] = 0;
    doc["scenes"] = {{{"nodes", {0, 1}}}};
    glm::vec3 eye(0.0f, 0.0f, 3.2f);
    doc["nodes"] = {{{"mesh", 0}, {"name", "sphere"}},
                    {{"name", "camera"},
                     {"camera", 0},
                     {"translation", {eye.x, eye.y, eye.z}},
                     {"rotation", gltfRotationTowards(-eye)}}};
    doc["cameras"] = {{{"type", "perspective"},
                       {"perspective", {{"yfov", 0.7}, {"znear", 0.05}, {"zfar", 100.0}}}}};
    doc["bufferViews"] = {gltfBufferView(0, count * 12), gltfBufferView(count * 12, count * 12),
                          gltfBufferView(count * 24, indices.size() * 2)};
    json position = gltfAccessor(0, 5126, int(count), "VEC3");
    position["min"] = {-1, -1, -1};
    position["max"] = {1, 1, 1};
    doc["accessors"] = {position, gltfAccessor(1, 5126, int(count), "VEC3"),
                        gltfAccessor(2, 5123, int(indices.size()), "SCALAR")};
    doc["materials"] = {{{"pbrMetallicRoughness",
                          {{"baseColorFactor", {baseColor.r, baseColor.g, baseColor.b, 1.0}},
                           {"metallicFactor", metallic},
                           {"roughnessFactor", roughness}}}}};
    doc["meshes"] = {
        {{"primitives",
          {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"indices", 2}, {"material", 0}}}}}};
    return writeGltf(name, doc, floats, indices);
}

float srgbToLinear(uint8_t v) {
    float c = float(v) / 255.0f;
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

float luminance(const std::vector<uint8_t>& rgba, size_t pixel) {
    return 0.2126f * srgbToLinear(rgba[pixel * 4]) + 0.7152f * srgbToLinear(rgba[pixel * 4 + 1]) +
           0.0722f * srgbToLinear(rgba[pixel * 4 + 2]);
}

// Covered pixels' linear colour (display curve `linear`, exposure 0 EV: the scene radiance).
struct CoveredStats {
    size_t covered = 0;
    double mean = 0.0, worst = 0.0; // mean channel value, largest deviation from `expected`
};
CoveredStats coveredStats(const std::vector<uint8_t>& rgba, float expected) {
    CoveredStats s;
    for (size_t p = 0; p < rgba.size() / 4; ++p) {
        if (rgba[p * 4 + 3] == 0) continue;
        ++s.covered;
        for (int c = 0; c < 3; ++c) {
            double v = srgbToLinear(rgba[p * 4 + c]);
            s.mean += v;
            s.worst = std::max(s.worst, std::abs(v - expected));
        }
    }
    if (s.covered) s.mean /= double(s.covered * 3);
    return s;
}

} // namespace

// The furnace: a uniform environment of radiance 0.5 and no light; white spheres of every kind
// reflect exactly 0.5 (linear tone curve): a dielectric's diffuse takes what its specular layer
// does not reflect, a white metal's multiple scattering returns what single scattering loses.
TEST(ImageBasedLighting, FurnaceWhiteSpheresReflectTheEnvironment) {
    const float radiance = 0.5f;
    std::string hdr = writeUniformHdr("furnace", radiance);
    for (float metallic : {0.0f, 1.0f})
        for (float roughness : {0.05f, 0.5f, 1.0f}) {
            SCOPED_TRACE(testing::Message()
                         << "metallic " << metallic << " roughness " << roughness);
            for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
                RenderOptions o = renderOptions(
                    writeSphere("furnace_sphere", metallic, roughness, glm::vec3(1.0f)), mode, 96,
                    96);
                o.camera = "camera";
                o.environment = hdr;
                o.environmentGiven = true;
                o.addDefaultSun = false;
                o.tonemap = Tonemap::Linear;
                RenderRun run = renderChecked(o);
                CoveredStats s = coveredStats(run.frames[0].rgba, radiance);
                std::printf("[ figures ] furnace %s metallic %.0f roughness %.2f: mean %.4f "
                            "(expected %.4f), worst pixel off by %.4f\n",
                            mode == RenderMode::Forward ? "forward" : "decoupled", metallic,
                            roughness, s.mean, radiance, s.worst);
                ASSERT_GT(s.covered, 3000u) << "the sphere must fill much of the image";
                EXPECT_NEAR(s.mean, radiance, 0.01 * radiance);
                EXPECT_LT(s.worst, 0.04 * radiance);
            }
        }
}

// A mirror sphere under the built-in sky, seen level from its side: its pixels are the sky and
// the ground reflected. Their mean luminance against the sky's above the horizon in the same
// image (the uncovered pixels of its upper half).
TEST(ImageBasedLighting, MirrorSphereReflectsTheSky) {
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        RenderOptions o = renderOptions(writeSphere("mirror_sphere", 1.0f, 0.0f, glm::vec3(1.0f)),
                                        mode, 160, 120);
        o.camera = "camera";
        o.addDefaultSun = true; // the sky is lit by the default sun
        RenderRun run = renderChecked(o);
        const std::vector<uint8_t>& rgba = run.frames[0].rgba;
        double sphere = 0.0, sky = 0.0;
        size_t sphereCount = 0, skyCount = 0;
        for (uint32_t y = 0; y < 60; ++y) // the upper half: above the horizon
            for (uint32_t x = 0; x < 160; ++x) {
                size_t p = size_t(y) * 160 + x;
                if (rgba[p * 4 + 3] == 0) sky += luminance(rgba, p), ++skyCount;
            }
        for (size_t p = 0; p < rgba.size() / 4; ++p)
            if (rgba[p * 4 + 3] != 0) sphere += luminance(rgba, p), ++sphereCount;
        ASSERT_GT(sphereCount, 2000u);
        ASSERT_GT(skyCount, 2000u);
        double ratio = (sphere / double(sphereCount)) / (sky / double(skyCount));
        std::printf("[ figures ] mirror sphere %s: mean luminance %.1f %% of the sky's\n",
                    mode == RenderMode::Forward ? "forward" : "decoupled", 100.0 * ratio);
        EXPECT_GE(ratio, 0.70);
    }
}

// Decoupled reuse with the environment turning 36 degrees a frame: every frame relights every
// surface, so the images with reuse on equal those with reuse off.
TEST(ImageBasedLighting, TurningEnvironmentLeavesNoStaleShading) {
    RenderOptions o = renderOptions("builtin:default", RenderMode::Decoupled, 192, 108);
    o.frames = 6;
    // The conformance environment: a bright window and coloured patches turn into view.
    o.environment = std::string(SHADEL_SOURCE_DIR) + "/tests/data/conformance/environment.hdr";
    o.environmentGiven = true;
    o.environmentSpinDegrees = 36.0f; // half a turn by the last frame
    ReuseRuns runs = renderReuseOnAndOff(o);
    double worst = worstFramePsnr(runs.on, runs.off);
    // Positive control: the turning is visible (the first and last frames differ).
    double turned = psnr(runs.off.frames.front().rgba, runs.off.frames.back().rgba);
    std::printf("[ figures ] turning environment: reuse on vs off worst frame %.2f dB; first vs "
                "last frame %.2f dB\n",
                worst, turned);
    EXPECT_LT(turned, 40.0);
    EXPECT_GE(worst, 45.0);
}

// A solid --background shows exactly the colour asked for under every tone curve (the radiance
// the curve maps onto it, radianceForDisplay), and the PNG keeps alpha as coverage.
TEST(ImageBasedLighting, SolidBackgroundIsExactAndPngAlphaIsCoverage) {
    const glm::vec3 colour(0.2f, 0.45f, 0.8f);
    for (Tonemap curve :
         {Tonemap::AcesNarkowicz, Tonemap::AcesHill, Tonemap::KhrPbrNeutral, Tonemap::Linear})
        for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
            SCOPED_TRACE(testing::Message() << "curve " << int(curve) << " mode " << int(mode));
            RenderOptions o = renderOptions(
                writeSphere("background_sphere", 0.0f, 0.5f, glm::vec3(0.8f)), mode, 64, 48);
            o.camera = "camera";
            o.tonemap = curve;
            o.backgroundEnvironment = false;
            o.backgroundColor = colour;
            o.out = tempPath("background.png");
            RenderRun run = renderChecked(o);
            const std::vector<uint8_t>& rgba = run.frames[0].rgba;
            int worst = 0;
            size_t uncovered = 0;
            for (size_t p = 0; p < rgba.size() / 4; ++p) {
                if (rgba[p * 4 + 3] != 0) continue;
                ++uncovered;
                for (int c = 0; c < 3; ++c)
                    worst = std::max(worst, std::abs(int(rgba[p * 4 + c]) -
                                                     int(std::lround(colour[c] * 255.0f))));
            }
            ASSERT_GT(uncovered, 500u);
            EXPECT_LE(worst, 1) << "background off by " << worst << " levels";
            int w = 0, h = 0, channels = 0;
            uint8_t* png = stbi_load(o.out.c_str(), &w, &h, &channels, 0);
            ASSERT_NE(png, nullptr);
            EXPECT_EQ(channels, 4);
            size_t alphaMismatches = 0;
            for (size_t p = 0; channels == 4 && p < size_t(w) * size_t(h); ++p)
                alphaMismatches += (png[p * 4 + 3] != 0) != (rgba[p * 4 + 3] != 0);
            stbi_image_free(png);
            std::remove(o.out.c_str());
            EXPECT_EQ(alphaMismatches, 0u);
        }
}

// bench --environment-compare runs forward and decoupled with the sky and without an
// environment, and its ratio is the sky's frame time over none's (one round: exactly).
TEST(ImageBasedLighting, BenchEnvironmentCompareRunsBothPathsWithAndWithout) {
    BenchOptions b;
    b.width = 96, b.height = 54;
    b.frames = 2;
    b.rounds = 1;
    b.compareEnvironment = true;
    nlohmann::json out = runBench(sharedGpu(), b);
    for (const char* mode : {"forward", "decoupled"}) {
        const nlohmann::json& sky = out["modes"][std::string(mode) + "_sky"];
        const nlohmann::json& none = out["modes"][std::string(mode) + "_none"];
        ASSERT_TRUE(sky.is_object() && none.is_object()) << out.dump().substr(0, 400);
        EXPECT_EQ(sky["mode"], mode);
        EXPECT_EQ(sky["settings"]["environment"], "builtin:sky");
        EXPECT_EQ(none["settings"]["environment"], "none");
        double skyMs = sky["frame_ms"]["median"], noneMs = none["frame_ms"]["median"];
        ASSERT_GT(noneMs, 0.0);
        EXPECT_DOUBLE_EQ(out["ratios"][std::string("environment_") + mode].get<double>(),
                         skyMs / noneMs);
    }
}
