// Environment sources and cache (render/environment): the built-in sky's colour and scale, the
// .hdr files (orientation, bad input), the on-disk cache (hits, corrupt files rebuilt).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include <stb/stb_image_write.h>

#include "core/error.h"
#include "core/worker_pool.h"
#include "render/environment/environment_cache.h"
#include "render/environment/environment_maps.h"
#include "render/environment/sky.h"
#include "scene/scene.h"
#include "temp_dir.h"

namespace shadel {
namespace {

constexpr float kDeg = 3.14159265f / 180.0f;

glm::vec3 towardElevation(float elevationDeg, float azimuthDeg) {
    float e = elevationDeg * kDeg, a = azimuthDeg * kDeg;
    return {std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a)};
}

float luminance(glm::vec3 c) {
    return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b;
}

TEST(EnvironmentSky, TheSunsIrradianceAtTheGroundIsTheScenesSun) {
    for (float elevation : {60.0f, 20.0f, 5.0f}) {
        SkyParameters sky;
        sky.sunDirection = -towardElevation(elevation, 30.0f);
        sky.sunColor = glm::vec3(3.0f, 2.8f, 2.5f);
        // The table's transmittance against a direct 20000-step integration along the ray.
        glm::dvec3 ground =
            skyTopOfAtmosphereIrradiance(sky) * skySunTransmittanceIntegrated(sky, 20000);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(ground[c] / sky.sunColor[c], 1.0, 0.01)
                << "elevation " << elevation << " channel " << c;
    }
}

TEST(EnvironmentSky, ZenithIsBluerThanTheHorizonAndTheSkyBrighterTowardTheSun) {
    WorkerPool pool(2);
    SkyParameters sky;
    sky.sunDirection = -towardElevation(35.0f, 0.0f);
    sky.sunColor = glm::vec3(3.0f);
    EquirectImage image = renderSky(sky, 128, 64, pool);
    glm::vec3 zenith = sampleEquirect(image, glm::vec3(0, 1, 0));
    glm::vec3 horizon = sampleEquirect(image, towardElevation(3.0f, 90.0f));
    EXPECT_GT(zenith.b / zenith.r, 1.2f * horizon.b / horizon.r)
        << "zenith b/r " << zenith.b / zenith.r << ", horizon " << horizon.b / horizon.r;
    EXPECT_GT(zenith.b, zenith.g);
    EXPECT_GT(zenith.g, zenith.r);
    glm::vec3 nearSun = sampleEquirect(image, towardElevation(35.0f, 12.0f));
    glm::vec3 away = sampleEquirect(image, towardElevation(35.0f, 120.0f));
    EXPECT_GT(luminance(nearSun), 2.0f * luminance(away));
    // The ground, seen straight down, is a Lambertian 0.3 lit by the sun and the sky.
    glm::dvec3 skyIrradiance(0.0);
    for (uint32_t y = 0; y < image.height / 2; ++y)
        for (uint32_t x = 0; x < image.width; ++x)
            skyIrradiance += glm::dvec3(image.at(x, y)) *
                             std::cos(3.14159265 * (y + 0.5) / image.height) *
                             equirectTexelSolidAngle(image.width, image.height, y);
    double expected = 0.3 / 3.14159265 * (3.0 * std::sin(35.0 * kDeg) + skyIrradiance.g);
    glm::vec3 nadir = sampleEquirect(image, glm::vec3(0, -1, 0));
    EXPECT_NEAR(nadir.g / expected, 1.0, 0.05) << "nadir " << nadir.g << " expected " << expected;
    EXPECT_GT(skyIrradiance.b, skyIrradiance.r);
}

TEST(EnvironmentFile, HdrRowsRunTopDownAndUpLightsFromAbove) {
    test::TempDir dir("envfile");
    // Top half red, bottom half blue.
    const int w = 64, h = 32;
    std::vector<float> rgb(size_t(w) * h * 3, 0.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) rgb[(size_t(y) * w + x) * 3 + (y < h / 2 ? 0 : 2)] = 2.0f;
    std::string path = dir.file("halves.hdr");
    ASSERT_TRUE(stbi_write_hdr(path.c_str(), w, h, 3, rgb.data()));
    EnvironmentRequest r;
    r.kind = EnvironmentKind::File, r.path = path;
    PrefilterSettings s;
    s.specularWidth = 64, s.specularLevels = 4, s.specularSamples = 32, s.brdfSize = 16;
    EnvironmentMaps maps = loadEnvironmentMaps(r, "", s, 2);
    glm::vec3 up = sampleEquirect(maps.irradiance, glm::vec3(0, 1, 0));
    glm::vec3 down = sampleEquirect(maps.irradiance, glm::vec3(0, -1, 0));
    EXPECT_GT(up.r, 5.0f * up.b);
    EXPECT_GT(down.b, 5.0f * down.r);
    EXPECT_NEAR(up.r, 2.0f, 0.01f); // facing up, the cosine lobe sees only the red half
}

TEST(EnvironmentFile, BadFilesAreInputErrorsNamingTheFile) {
    test::TempDir dir("envbad");
    auto expectError = [&](const std::string& path, const std::string& reason) {
        EnvironmentRequest r;
        r.kind = EnvironmentKind::File, r.path = path;
        try {
            loadEnvironmentMaps(r, dir.path.string(), {}, 2);
            ADD_FAILURE() << path << ": no error";
        } catch (const InputError& e) {
            std::string what = e.what();
            EXPECT_NE(what.find(path), std::string::npos) << what;
            EXPECT_NE(what.find(reason), std::string::npos) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        }
    };
    expectError(dir.file("missing.hdr"), "cannot open");
    std::string garbage = dir.file("garbage.hdr");
    std::ofstream(garbage) << "#?RADIANCE\nthis is not a picture\n";
    expectError(garbage, "HDR");
    std::string huge = dir.file("huge.hdr");
    std::ofstream(huge) << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 10000 +X 20000\n";
    expectError(huge, "20000x10000");
    std::string truncated = dir.file("truncated.hdr");
    std::ofstream(truncated) << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 32 +X 64\n\x02\x02";
    expectError(truncated, truncated);
    std::string png = dir.file("picture.png");
    std::ofstream(png) << "x";
    expectError(png, ".hdr or an .exr");
    std::string exr = dir.file("bad.exr");
    std::ofstream(exr) << "not an exr at all";
    expectError(exr, "EXR");
    Scene scene;
    EXPECT_THROW(environmentRequest("builtin:moon", true, scene, {0, -1, 0}, {1, 1, 1}),
                 InputError);
}

TEST(EnvironmentCache, HitsAfterTheFirstBuildAndACorruptFileIsRebuilt) {
    test::TempDir dir("envcache");
    Scene scene;
    scene.environment = Scene::Environment::Hemisphere;
    EnvironmentRequest r = environmentRequest("builtin:sky", false, scene, {0, -1, 0}, {1, 1, 1});
    ASSERT_EQ(r.kind, EnvironmentKind::Hemisphere);
    PrefilterSettings s;
    s.specularWidth = 64, s.specularLevels = 4, s.specularSamples = 32, s.brdfSize = 16;
    EnvironmentMaps first = loadEnvironmentMaps(r, dir.path.string(), s, 2);
    EXPECT_FALSE(first.fromCache);
    EnvironmentMaps second = loadEnvironmentMaps(r, dir.path.string(), s, 2);
    EXPECT_TRUE(second.fromCache);
    EXPECT_EQ(second.specular.back().texels, first.specular.back().texels);
    EXPECT_EQ(second.irradiance.texels, first.irradiance.texels);
    // Damage every cache file: truncated, or one byte flipped in the middle.
    for (int damage = 0; damage < 2; ++damage) {
        for (const auto& entry : std::filesystem::directory_iterator(dir.path)) {
            std::string path = entry.path().string();
            auto size = std::filesystem::file_size(path);
            if (damage == 0) {
                std::filesystem::resize_file(path, size / 2);
            } else {
                std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
                f.seekp(std::streamoff(size / 2));
                f.put(char(0x5A));
            }
        }
        EnvironmentMaps rebuilt = loadEnvironmentMaps(r, dir.path.string(), s, 2);
        EXPECT_FALSE(rebuilt.fromCache) << "damage " << damage;
        EXPECT_EQ(rebuilt.irradiance.texels, first.irradiance.texels);
        EXPECT_EQ(rebuilt.brdf.texels, first.brdf.texels);
        EXPECT_TRUE(loadEnvironmentMaps(r, dir.path.string(), s, 2).fromCache)
            << "the rebuilt maps were written back";
    }
    // Another source is another key.
    r.skyColor += glm::vec3(0.1f);
    EXPECT_FALSE(loadEnvironmentMaps(r, dir.path.string(), s, 2).fromCache);
}

} // namespace
} // namespace shadel
