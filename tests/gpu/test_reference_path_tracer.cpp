// The reference path tracer (--mode reference, render/reference) judged against analytic light
// transport:
// - the furnace: a white Lambertian (albedo 1, no specular layer) in a uniform environment of
//   radiance L reflects exactly L, however many bounces its paths take;
// - a Lambertian plane under a directional light of irradiance E at angle theta shows
//   albedo / pi * E * cos(theta) (the forward path's convention: a light's colour x intensity is
//   the irradiance it gives a surface facing it);
// - noise: two seeds of builtin:cornell agree as their sample counts say; one seed twice is the
//   same image.
#include "gpu_test_env.h"
#include "scene_files.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <sys/wait.h>

#include "app/exr_file.h"

using namespace shadel;
using namespace shadel::test;
using nlohmann::json;

namespace {

constexpr float kPi = 3.14159265358979f;

bool canTrace() {
    return sharedGpu().device.optional.rayQuery;
}

// A Lambertian material of `albedo`: KHR_materials_specular with a factor of 0 removes the
// dielectric's specular layer, so the BRDF is albedo / pi exactly.
json lambertian(float albedo) {
    return {{"pbrMetallicRoughness",
             {{"baseColorFactor", {albedo, albedo, albedo, 1.0}},
              {"metallicFactor", 0.0},
              {"roughnessFactor", 1.0}}},
            {"extensions", {{"KHR_materials_specular", {{"specularFactor", 0.0}}}}}};
}

// Appends a UV sphere (centre, radius) to the arrays, its normals the exact ones.
void appendSphere(glm::vec3 centre, float radius, std::vector<float>& positions,
                  std::vector<float>& normals, std::vector<uint16_t>& indices) {
    const int rings = 48, segments = 96;
    uint16_t base = uint16_t(positions.size() / 3);
    for (int r = 0; r <= rings; ++r)
        for (int s = 0; s <= segments; ++s) {
            float theta = kPi * float(r) / rings, phi = 2.0f * kPi * float(s) / segments;
            glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta),
                        std::sin(theta) * std::sin(phi));
            glm::vec3 p = centre + n * radius;
            positions.insert(positions.end(), {p.x, p.y, p.z});
            normals.insert(normals.end(), {n.x, n.y, n.z});
        }
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            uint16_t a = uint16_t(base + r * (segments + 1) + s), b = uint16_t(a + segments + 1);
            indices.insert(indices.end(),
                           {a, uint16_t(a + 1), b, uint16_t(a + 1), uint16_t(b + 1), b});
        }
}

// One mesh of the given triangles and material, a camera at `eye` looking at `target`, and
// optionally a directional light of `intensity` travelling along `lightDir`.
std::string writeScene(const std::string& name, const std::vector<float>& positions,
                       const std::vector<float>& normals, const std::vector<uint16_t>& indices,
                       json material, glm::vec3 eye, glm::vec3 target, float intensity = 0.0f,
                       glm::vec3 lightDir = glm::vec3(0, -1, 0)) {
    size_t count = positions.size() / 3;
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (size_t i = 0; i < count; ++i)
        for (int c = 0; c < 3; ++c)
            lo[c] = std::min(lo[c], positions[i * 3 + c]),
            hi[c] = std::max(hi[c], positions[i * 3 + c]);
    std::vector<float> floats = positions;
    floats.insert(floats.end(), normals.begin(), normals.end());
    json doc;
    doc["asset"] = {{"version", "2.0"}};
    doc["scene"] = 0;
    json nodes = {{{"mesh", 0}, {"name", "object"}},
                  {{"name", "camera"},
                   {"camera", 0},
                   {"translation", {eye.x, eye.y, eye.z}},
                   {"rotation", gltfRotationTowards(target - eye)}}};
    json sceneNodes = {0, 1};
    doc["extensionsUsed"] = {"KHR_materials_specular"};
    if (intensity > 0.0f) {
        doc["extensionsUsed"].push_back("KHR_lights_punctual");
        doc["extensions"]["KHR_lights_punctual"]["lights"] = {
            {{"type", "directional"}, {"intensity", intensity}, {"color", {1, 1, 1}}}};
        nodes.push_back({{"name", "sun"},
                         {"rotation", gltfRotationTowards(lightDir)},
                         {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
        sceneNodes.push_back(2);
    }
    doc["nodes"] = nodes;
    doc["scenes"] = {{{"nodes", sceneNodes}}};
    doc["cameras"] = {{{"type", "perspective"},
                       {"perspective", {{"yfov", 0.7}, {"znear", 0.05}, {"zfar", 100.0}}}}};
    doc["bufferViews"] = {gltfBufferView(0, count * 12), gltfBufferView(count * 12, count * 12),
                          gltfBufferView(count * 24, indices.size() * 2)};
    json position = gltfAccessor(0, 5126, int(count), "VEC3");
    position["min"] = {lo.x, lo.y, lo.z};
    position["max"] = {hi.x, hi.y, hi.z};
    doc["accessors"] = {position, gltfAccessor(1, 5126, int(count), "VEC3"),
                        gltfAccessor(2, 5123, int(indices.size()), "SCALAR")};
    doc["materials"] = {material};
    doc["meshes"] = {
        {{"primitives",
          {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"indices", 2}, {"material", 0}}}}}};
    return writeGltf(name, doc, floats, indices);
}

RenderOptions referenceOptions(const std::string& scene, uint32_t w, uint32_t h) {
    RenderOptions o = renderOptions(scene, RenderMode::Reference, w, h);
    o.progress = false;
    o.tonemap = Tonemap::Linear;
    return o;
}

// The accumulated mean of the run's last frame (--capture reference): RGBA floats.
struct HdrImage {
    uint32_t width = 0, height = 0;
    std::vector<float> rgba;
};
HdrImage renderHdr(RenderOptions o, const std::string& name) {
    o.captures = {"reference"};
    o.captureDir = tempPath(name);
    RenderRun run = renderChecked(o);
    EXPECT_EQ(run.captureFiles.size(), 1u);
    HdrImage image;
    if (run.captureFiles.empty()) return image;
    std::ifstream in(run.captureFiles[0], std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), {});
    image.rgba = decodeExrRgba(bytes, image.width, image.height);
    EXPECT_EQ(run.stats["reference"]["spp_total"].get<uint32_t>(),
              o.frames * o.reference.samplesPerFrame);
    return image;
}

// Covered pixels (coverage 1: every path met a surface) against `expected`: their mean and the
// largest relative deviation of one pixel's channel.
struct Agreement {
    size_t pixels = 0;
    double mean = 0.0, worst = 0.0;
};
Agreement agreement(const HdrImage& image, double expected) {
    Agreement a;
    for (size_t p = 0; p < image.rgba.size() / 4; ++p) {
        if (image.rgba[p * 4 + 3] < 1.0f) continue;
        ++a.pixels;
        for (int c = 0; c < 3; ++c) {
            double v = image.rgba[p * 4 + c];
            a.mean += v;
            a.worst = std::max(a.worst, std::abs(v - expected) / expected);
        }
    }
    if (a.pixels) a.mean /= double(a.pixels * 3);
    return a;
}

} // namespace

// A device without ray queries: --mode reference is one line naming the mode and what is
// missing, exit 2; so are bad values of its options.
TEST(ReferencePathTracer, WithoutRayQueryOrWithBadOptionsOneClearError) {
    std::string err;
    EXPECT_EQ(runShadel("SHADEL_DISABLE_RAY_QUERY=1",
                        "render --scene builtin:cornell --size 32x18 --mode reference", err),
              2);
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_NE(err.find("--mode reference"), std::string::npos) << err;
    EXPECT_NE(err.find("VK_KHR_ray_query"), std::string::npos) << err;
    for (const char* bad : {"--spp 0", "--max-bounces -1", "--seed x"}) {
        EXPECT_EQ(runShadel("", std::string("render --size 32x18 --mode reference ") + bad, err), 2)
            << bad;
        EXPECT_NE(err.find(std::string(bad).substr(0, std::string(bad).find(' '))),
                  std::string::npos)
            << err;
    }
}

// A white sphere alone: every path leaves it after one bounce, and its estimate (the
// environment's cosine sample and the BRDF's, weighted half and half) is exactly L, except when
// a sample leaves below the hit triangle's plane (the shading normal is the sphere's, up to 1.9
// degrees off the facet's): measured 2 of 17000 paths' samples lose their half at 4 paths per
// pixel (a pixel 12.5 % low), so at 256 paths one such loss moves a pixel by 0.2 % and the
// worst pixel measures the bias alone. The sphere on a white slab adds paths of many bounces
// between the two (Russian roulette ends them: unbiased); the mean of its pixels must still be L
// (measured 0.12 % low: the pixels by the contact, where the offset ray origins of one object
// start inside the other).
TEST(ReferencePathTracer, FurnaceWhiteLambertianReflectsTheEnvironment) {
    SHADEL_REQUIRE(canTrace(), "ray query (VK_KHR_ray_query) on the device");
    const float radiance = 0.5f;
    std::string hdr = writeUniformHdr("reference_furnace", radiance);
    std::vector<float> positions, normals;
    std::vector<uint16_t> indices;
    appendSphere(glm::vec3(0.0f), 1.0f, positions, normals, indices);
    for (bool slab : {false, true}) {
        SCOPED_TRACE(slab ? "sphere on a slab" : "sphere");
        if (slab) {
            const float centre[3] = {0.0f, -1.1f, 0.0f}, half[3] = {2.5f, 0.1f, 2.5f};
            // (appendBox numbers from the box's first vertex; here it follows the sphere's)
            uint16_t first = uint16_t(positions.size() / 3);
            size_t firstIndex = indices.size();
            appendBox(centre, half, positions, normals, indices);
            for (size_t i = firstIndex; i < indices.size(); ++i) indices[i] += first;
        }
        std::string scene = writeScene(slab ? "reference_furnace_slab" : "reference_furnace",
                                       positions, normals, indices, lambertian(1.0f),
                                       glm::vec3(0.0f, 1.2f, 3.6f), glm::vec3(0.0f, -0.5f, 0.0f));
        RenderOptions o = referenceOptions(scene, 64, 64);
        o.camera = "camera";
        o.environment = hdr;
        o.environmentGiven = true;
        o.addDefaultSun = false;
        o.frames = 4;
        o.reference.samplesPerFrame = 64;
        HdrImage image = renderHdr(o, slab ? "furnace_slab" : "furnace_sphere");
        Agreement a = agreement(image, radiance);
        std::printf("[ figures ] furnace (%s), %u paths per pixel: %zu covered pixels, mean %.5f "
                    "(expected %.5f, off by %.3f%%), worst pixel channel off by %.3f%%\n",
                    slab ? "sphere on a slab" : "sphere", o.frames * o.reference.samplesPerFrame,
                    a.pixels, a.mean, radiance, 100.0 * std::abs(a.mean - radiance) / radiance,
                    100.0 * a.worst);
        ASSERT_GT(a.pixels, 1000u) << "the object must fill much of the image";
        EXPECT_NEAR(a.mean, radiance, 0.01 * radiance);
        if (!slab) { // (where the sphere touches the slab, single pixels measure 13 % low)
            EXPECT_LT(a.worst, 0.01) << "every covered pixel is L";
        }
    }
}

// A Lambertian slab's top face under a directional light at 60 degrees from its normal, no
// environment: the radiance is albedo / pi * E * cos(60 deg) everywhere on it (its bounces
// leave upward into nothing).
TEST(ReferencePathTracer, LambertianPlaneUnderADirectionalLight) {
    SHADEL_REQUIRE(canTrace(), "ray query (VK_KHR_ray_query) on the device");
    std::vector<float> positions, normals;
    std::vector<uint16_t> indices;
    const float centre[3] = {0.0f, -0.1f, 0.0f}, half[3] = {20.0f, 0.1f, 20.0f};
    appendBox(centre, half, positions, normals, indices);
    const float albedo = 0.6f, irradiance = 3.0f, theta = glm::radians(60.0f);
    glm::vec3 travel(std::sin(theta), -std::cos(theta), 0.0f);
    std::string scene =
        writeScene("reference_plane", positions, normals, indices, lambertian(albedo),
                   glm::vec3(0.0f, 2.0f, 2.0f), glm::vec3(0.0f), irradiance, travel);
    RenderOptions o = referenceOptions(scene, 64, 64);
    o.camera = "camera";
    o.environment = "none";
    o.environmentGiven = true;
    o.addDefaultSun = false;
    o.reference.samplesPerFrame = 2;
    HdrImage image = renderHdr(o, "plane");
    double expected = albedo / kPi * irradiance * std::cos(theta);
    Agreement a = agreement(image, expected);
    std::printf("[ figures ] Lambertian plane, directional light at 60 degrees: mean %.5f "
                "(expected %.5f), worst pixel channel off by %.4f%%\n",
                a.mean, expected, 100.0 * a.worst);
    ASSERT_EQ(a.pixels, size_t(64 * 64)) << "the plane fills the image";
    EXPECT_LT(a.worst, 0.002);
}

// Independent noise: two seeds of builtin:cornell differ by noise alone, which falls as the
// paths grow (4 x the paths: +6 dB for Gaussian noise; measured +3.7 dB, the noise being
// fireflies of paths that find the rim of the ceiling's opening, lit from 0.7 m by the spot:
// 20.9 dB at 256 paths per pixel, 40 dB would take about 80 x as many); one seed twice is the
// same image. The stats, the pass list and the ray
// count say what ran.
TEST(ReferencePathTracer, SeedsGiveIndependentNoiseAndTheSameSeedTheSameImage) {
    SHADEL_REQUIRE(canTrace(), "ray query (VK_KHR_ray_query) on the device");
    RenderOptions o = referenceOptions("builtin:cornell", 64, 64);
    o.tonemap = Tonemap::AcesNarkowicz;
    o.reference.samplesPerFrame = 64;
    o.reference.seed = 1;
    RenderRun a = renderChecked(o);
    RenderRun again = renderChecked(o);
    o.reference.seed = 2;
    RenderRun b = renderChecked(o);
    EXPECT_EQ(a.frames.back().rgba, again.frames.back().rgba) << "the same seed, the same image";
    EXPECT_NE(a.frames.back().rgba, b.frames.back().rgba);
    double few = psnr(a.frames.back().rgba, b.frames.back().rgba);
    o.frames = 4; // 256 paths per pixel, over frames
    RenderRun many = renderChecked(o);
    o.reference.seed = 1;
    RenderRun manyOther = renderChecked(o);
    double more = psnr(many.frames.back().rgba, manyOther.frames.back().rgba);
    std::printf("[ figures ] builtin:cornell 64x64: seeds 1 and 2 agree to %.2f dB at 64 paths per "
                "pixel, %.2f dB at 256\n",
                few, more);
    EXPECT_GE(more, 19.4) << "measured " << more << " dB at 256 paths per pixel";
    EXPECT_GE(more - few, 2.2) << "4 x the paths: measured " << more - few << " dB more";
    const json& s = many.stats;
    EXPECT_EQ(s["mode"], "reference");
    EXPECT_EQ(s["reference"]["spp_total"].get<uint32_t>(), 256u);
    EXPECT_EQ(s["reference"]["seed"].get<uint32_t>(), 2u);
    EXPECT_GT(s["rays_traced"].get<uint64_t>(), uint64_t(64 * 64 * 64));
    bool traced = false, tonemapped = false;
    for (const json& p : s["passes"]) {
        traced |= p["name"] == "referencePathTrace";
        tonemapped |= p["name"] == "tonemap";
    }
    EXPECT_TRUE(traced && tonemapped) << s["passes"].dump();
}
