// Textured light kinds: gobo spots project their texture, textured area lights light
// with their texture's colour; both paths and the culling / spectra permutations agree on
// builtin:textured-lights.
#include "gpu_test_env.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <glm/glm.hpp>

#include "app/exr_file.h"
#include "render/camera.h"
#include "render/gpu_scene.h"
#include "render/lighting/light_culling.h"
#include "scene/builtin_scenes.h"

using namespace shadel;
using namespace shadel::test;

namespace {

constexpr uint32_t kW = 320, kH = 180;

// The frame's linear HDR pixels (RGBA float), rendered with --out FILE.exr.
std::vector<float> renderLinear(RenderOptions o, RenderRun& run) {
    o.out = tempPath("light-textures.exr");
    run = renderChecked(o);
    std::ifstream in(o.out, std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), {});
    std::filesystem::remove(o.out);
    uint32_t w = 0, h = 0;
    std::vector<float> hdr = decodeExrRgba(bytes, w, h);
    EXPECT_EQ(w, o.width);
    EXPECT_EQ(h, o.height);
    return hdr;
}

// Where pixel (px, py) of the scene's main camera meets the plane dot(n, p) = d.
glm::vec3 onPlane(const CameraView& v, uint32_t px, uint32_t py, glm::vec3 n, float d) {
    glm::mat4 inv = glm::inverse(v.proj * v.view);
    glm::vec2 ndc((float(px) + 0.5f) / float(kW) * 2.0f - 1.0f,
                  (float(py) + 0.5f) / float(kH) * 2.0f - 1.0f);
    glm::vec4 a = inv * glm::vec4(ndc, 1.0f, 1.0f), b = inv * glm::vec4(ndc, 0.5f, 1.0f);
    glm::vec3 p0 = glm::vec3(a) / a.w, p1 = glm::vec3(b) / b.w;
    float t = (d - glm::dot(n, p0)) / glm::dot(n, p1 - p0);
    return p0 + (p1 - p0) * t;
}

float srgbDecode(uint8_t byte) {
    float c = float(byte) / 255.0f;
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

glm::vec3 texel(const Texture& t, int x, int y) {
    x = std::clamp(x, 0, int(t.width) - 1), y = std::clamp(y, 0, int(t.height) - 1);
    const uint8_t* p = &t.rgba8[(size_t(y) * t.width + size_t(x)) * 4];
    return {srgbDecode(p[0]), srgbDecode(p[1]), srgbDecode(p[2])};
}

float luminance(glm::vec3 c) {
    return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b;
}

const Light& lightNamed(const Scene& scene, const std::string& name) {
    for (const Light& l : scene.lights)
        if (l.name == name) return l;
    throw std::runtime_error("no light " + name);
}

RenderOptions texturedLights(RenderMode mode, uint32_t w = kW, uint32_t h = kH) {
    return renderOptions("builtin:textured-lights", mode, w, h);
}

} // namespace

// The window gobo on the back wall: wall pixels inside the spot's inner cone (full intensity)
// where the texture is bright (the panes) against those where it is dark (frame and cross,
// away from their edges). Bright and dark are read from the texture at the UV the spot projects
// there, computed here on the CPU from the light's placement.
TEST(LightTextures, GoboPatternFollowsItsTexture) {
    RenderRun run;
    std::vector<float> hdr = renderLinear(texturedLights(RenderMode::Forward), run);
    Scene scene = makeBuiltinScene("textured-lights");
    CameraView view = makeCameraView(findCamera(scene, ""), kW, kH);
    const Light& gobo = lightNamed(scene, "window gobo");
    ASSERT_GE(gobo.texture, 0);
    const Texture& tex = scene.textures[size_t(gobo.texture)];
    glm::vec3 dir = glm::normalize(gobo.direction);
    glm::vec3 right = glm::normalize(gobo.axis - dir * glm::dot(gobo.axis, dir));
    glm::vec3 up = glm::cross(right, dir); // upright seen from behind the light
    float scale = 0.5f * gobo.textureTiling / std::tan(gobo.outerConeAngle);
    double bright = 0, dark = 0;
    int brightPixels = 0, darkPixels = 0;
    for (uint32_t y = 0; y < kH; ++y)
        for (uint32_t x = 0; x < kW; ++x) {
            glm::vec3 p = onPlane(view, x, y, {0, 0, 1}, -2.9f); // the back wall's face
            if (p.x < -1.0f || p.x > 5.0f || p.y < 0.3f || p.y > 3.2f) continue;
            glm::vec3 d = glm::normalize(p - gobo.position);
            float z = glm::dot(dir, d);
            if (std::acos(std::min(z, 1.0f)) > gobo.innerConeAngle * 0.95f) continue;
            glm::vec2 uv(0.5f + glm::dot(right, d) / z * scale, 0.5f - glm::dot(up, d) / z * scale);
            int tx = int(std::floor(uv.x * float(tex.width))),
                ty = int(std::floor(uv.y * float(tex.height)));
            // The texel and its neighbours within 3 texels (a pixel spans ~2 here) agree.
            float lo = 1e9f, hi = -1e9f;
            for (int dy = -3; dy <= 3; ++dy)
                for (int dx = -3; dx <= 3; ++dx) {
                    float l = luminance(texel(tex, tx + dx, ty + dy));
                    lo = std::min(lo, l), hi = std::max(hi, l);
                }
            size_t i = (size_t(y) * kW + x) * 4;
            float lum = luminance({hdr[i], hdr[i + 1], hdr[i + 2]});
            if (lo > 0.8f) bright += lum, brightPixels++;
            if (hi < 0.02f) dark += lum, darkPixels++;
        }
    ASSERT_GT(brightPixels, 100) << "the spot's panes are on screen";
    ASSERT_GT(darkPixels, 20) << "the window's cross is on screen";
    double meanBright = bright / brightPixels, meanDark = dark / darkPixels;
    std::printf("[ figures ] gobo on the wall: pane %.4f, cross %.4f (linear luminance), ratio "
                "%.1f (%d / %d pixels)\n",
                meanBright, meanDark, meanBright / meanDark, brightPixels, darkPixels);
    EXPECT_GT(meanBright, 0.1) << "the gobo lights the wall";
    EXPECT_GE(meanBright, 8.0 * meanDark) << "where the texture is dark the spot does not light";
}

// The panel faces the side wall, the only light reaching the part of it in front of the panel
// (the moon comes from the other side, the sign's range stops short, the gobos point away):
// the wall is lit there, in the colour of the panel texture's mean (the wall is grey; the
// texture's orange/yellow checker is finer than the diffuse integral's cells).
TEST(LightTextures, AreaLightLightsTheWallInItsTexturesMeanColour) {
    RenderRun run;
    std::vector<float> hdr = renderLinear(texturedLights(RenderMode::Forward), run);
    Scene scene = makeBuiltinScene("textured-lights");
    CameraView view = makeCameraView(findCamera(scene, ""), kW, kH);
    const Light& panel = lightNamed(scene, "panel");
    ASSERT_EQ(panel.type, LightType::Area);
    const Texture& tex = scene.textures[size_t(panel.texture)];
    glm::dvec3 mean(0.0);
    for (uint32_t y = 0; y < tex.height; ++y)
        for (uint32_t x = 0; x < tex.width; ++x) mean += glm::dvec3(texel(tex, int(x), int(y)));
    mean /= double(tex.width * tex.height);
    glm::dvec3 lit(0.0);
    int pixels = 0;
    for (uint32_t y = 0; y < kH; ++y)
        for (uint32_t x = 0; x < kW; ++x) {
            glm::vec3 p = onPlane(view, x, y, {1, 0, 0}, -4.9f); // the side wall's face
            if (p.z < 0.1f || p.z > 0.9f || p.y < 1.0f || p.y > 2.2f) continue;
            size_t i = (size_t(y) * kW + x) * 4;
            lit += glm::dvec3(hdr[i], hdr[i + 1], hdr[i + 2]);
            pixels++;
        }
    ASSERT_GT(pixels, 30);
    lit /= double(pixels);
    // The ambient and sky alone give at most (ambient + 0.15 sky) x albedo 0.7.
    double ambientBound = 0.7 * luminance(scene.ambientColor + 0.15f * scene.skyColor);
    glm::dvec3 chromaLit = lit / (lit.r + lit.g + lit.b);
    glm::dvec3 chromaMean = mean / (mean.r + mean.g + mean.b);
    std::printf("[ figures ] area light on the side wall: linear (%.3f %.3f %.3f), chromaticity "
                "(%.3f %.3f %.3f) vs the texture mean's (%.3f %.3f %.3f)\n",
                lit.r, lit.g, lit.b, chromaLit.r, chromaLit.g, chromaLit.b, chromaMean.r,
                chromaMean.g, chromaMean.b);
    EXPECT_GT(luminance(glm::vec3(lit)), 20.0 * ambientBound) << "the area light lights the wall";
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(chromaLit[c], chromaMean[c], 0.03) << "channel " << c;
}

// The shared lighting code gives the shadel path the same textured lights.
TEST(LightTextures, DecoupledMatchesForward) {
    RenderRun fwd = renderChecked(texturedLights(RenderMode::Forward));
    RenderRun dec = renderChecked(texturedLights(RenderMode::Decoupled));
    double p = psnr(fwd.frames[0].rgba, dec.frames[0].rgba);
    std::printf("[ figures ] textured-lights %ux%u: PSNR(decoupled, forward) = %.2f dB\n", kW, kH,
                p);
    EXPECT_GE(p, 35.0);
    EXPECT_EQ(dec.stats["reconstruction_misses"].get<uint64_t>(), 0u);
    double sum = 0; // not a black pair
    for (size_t i = 0; i < fwd.frames[0].rgba.size(); i += 4) sum += fwd.frames[0].rgba[i + 1];
    EXPECT_GT(sum / (double(kW) * kH), 8.0);
}

// Tiled culling (area lights by their bounds and back side, gobos as spots) and the spectra
// permutations (tiles without gobos or area lights run code without them) change nothing.
TEST(LightTextures, CullingAndSpectraChangeNothing) {
    RenderOptions o = texturedLights(RenderMode::Forward);
    o.lightCulling = LightCulling::None;
    RenderRun none = renderChecked(o);
    o.lightCulling = LightCulling::Tiled;
    RenderRun tiled = renderChecked(o);
    o.spectra = Spectra::On;
    RenderRun spectra = renderChecked(o);
    double pTiled = psnr(none.frames[0].rgba, tiled.frames[0].rgba);
    double pSpectra = psnr(tiled.frames[0].rgba, spectra.frames[0].rgba);
    std::printf("[ figures ] textured-lights %ux%u forward: PSNR(tiled, none) = %.2f dB, "
                "PSNR(spectra on, off) = %.2f dB\n",
                kW, kH, pTiled, pSpectra);
    EXPECT_GE(pTiled, 45.0);
    EXPECT_GE(pSpectra, 50.0);
    const auto& s = tiled.stats;
    uint64_t tiles = s["light_tiles"].get<uint64_t>();
    ASSERT_GT(tiles, 0u) << "the scene has enough lights in view to be culled by tiles";
    EXPECT_LT(s["light_tile_pairs"].get<uint64_t>(), tiles * (s["lights"].get<uint64_t>() - 1) / 2)
        << "tiles keep fewer than half the lights";
    // Every tile that shows a surface needs the moon's shadow: those are the lit tiles.
    const auto& features = spectra.stats["tile_features"];
    uint64_t lit = features["shadows"].get<uint64_t>();
    uint64_t projected = features["projected"].get<uint64_t>();
    uint64_t area = features["area"].get<uint64_t>();
    std::printf("[ figures ] tiles: %llu, with surfaces %llu, needing gobos %llu, area lights "
                "%llu\n",
                (unsigned long long)tiles, (unsigned long long)lit, (unsigned long long)projected,
                (unsigned long long)area);
    EXPECT_GT(projected, 0u);
    EXPECT_GT(area, 0u);
    EXPECT_LT(projected, lit * 3 / 4) << "the gobos' cones are culled from tiles they miss";
    EXPECT_LT(area, lit) << "area lights are culled by their range and their back side";
}

// The scene light -> GpuLight conversion of the two kinds: a spot is a gobo only with a
// texture, its UV scale fills the outer cone `textureTiling` times and its right axis is made
// orthogonal to its direction; an area light carries its half extents, and its culling reach is
// its range plus its half diagonal.
TEST(LightTextures, GpuLightsOfGobosAndAreaLights) {
    std::vector<uint32_t> blockerLists;
    Light spot;
    spot.type = LightType::Spot;
    spot.direction = {0, -1, 0};
    spot.axis = {1, 0.5f, 0};
    spot.outerConeAngle = 0.5f;
    spot.textureTiling = 2.0f;
    gpu::GpuLight plain = gpuLight(spot, blockerLists);
    EXPECT_EQ(plain.flags & LIGHT_FLAG_PROJECTED, 0u);
    EXPECT_EQ(plain.textureSlot, NO_TEXTURE);
    gpu::GpuLight gobo = gpuLight(spot, blockerLists, 7u);
    EXPECT_NE(gobo.flags & LIGHT_FLAG_PROJECTED, 0u);
    EXPECT_EQ(gobo.textureSlot, 7u);
    EXPECT_NEAR(gobo.textureScale, 0.5f * 2.0f / std::tan(0.5f), 1e-5f);
    EXPECT_NEAR(glm::dot(gobo.axis, gobo.direction), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::length(gobo.axis), 1.0f, 1e-6f);

    Light area;
    area.type = LightType::Area;
    area.direction = {0, 0, 1};
    area.axis = {1, 0, 0};
    area.areaSize = {2.4f, 0.6f};
    area.range = 4.0f;
    gpu::GpuLight g = gpuLight(area, blockerLists, 3u);
    EXPECT_EQ(g.type, LIGHT_AREA);
    EXPECT_EQ(g.textureSlot, 3u);
    EXPECT_FLOAT_EQ(g.halfLength, 1.2f);
    EXPECT_FLOAT_EQ(g.radius, 0.3f);
    EXPECT_EQ(g.flags & LIGHT_FLAG_PROJECTED, 0u);
    EXPECT_NEAR(lightReach(g), 4.0f + std::hypot(1.2f, 0.3f), 1e-5f);
}
