// --inspect X,Y (shaders/debug/inspect.glsl through shaderPrintF): what the shading printed for a
// pixel agrees with a CPU evaluation of the same material and lights at that surface point, and
// with the pixel the frame shows.
#include "gpu_test_env.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "common/print_labels.h"
#include "render/debug/inspect.h"
#include "scene/load.h"

using namespace shadel;
using namespace shadel::test;

namespace {

constexpr float kPi = 3.14159265358979f;

// The glTF metal/rough BRDF written from the glTF 2.0 specification (GGX, height-correlated
// Smith, Schlick, Lambert), for this test only: an oracle independent of lighting.glsl.
glm::vec3 brdf(glm::vec3 base, float metallic, float roughness, glm::vec3 n, glm::vec3 v,
               glm::vec3 l, glm::vec3 radiance) {
    float nl = glm::dot(n, l);
    if (nl <= 0.0f) return glm::vec3(0.0f);
    glm::vec3 h = glm::normalize(v + l);
    float nv = std::max(glm::dot(n, v), 1e-4f);
    float nh = std::max(glm::dot(n, h), 0.0f);
    float vh = std::max(glm::dot(v, h), 0.0f);
    // Lights floor perceptual roughness at 0.04 (a point light on a mirror is a delta).
    float r = std::max(roughness, 0.04f);
    float a = r * r, a2 = a * a;
    float d = nh * nh * (a2 - 1.0f) + 1.0f;
    float ggx = a2 / (kPi * d * d);
    float gv = nl * std::sqrt(nv * nv * (1.0f - a2) + a2);
    float gl = nv * std::sqrt(nl * nl * (1.0f - a2) + a2);
    float vis = 0.5f / std::max(gv + gl, 1e-5f);
    // glTF 2.0, appendix B: mix(dielectric, metal, metallic); the dielectric's Fresnel (F0 0.04)
    // weights its diffuse and its specular, the metal's (F0 = base colour) its specular.
    float schlick = std::pow(1.0f - vh, 5.0f);
    float fDielectric = 0.04f + 0.96f * schlick;
    glm::vec3 fMetal = base + (1.0f - base) * schlick;
    glm::vec3 dielectric = (1.0f - fDielectric) * base / kPi + glm::vec3(fDielectric * ggx * vis);
    glm::vec3 metal = fMetal * ggx * vis;
    return glm::mix(dielectric, metal, metallic) * radiance * nl;
}

float rangeAttenuation(float dist, float range) {
    float inv = 1.0f / std::max(dist * dist, 1e-4f);
    if (range <= 0.0f) return inv;
    float r = dist / range;
    float w = std::clamp(1.0f - r * r * r * r, 0.0f, 1.0f);
    return inv * w * w;
}

struct Printed {
    std::map<uint32_t, std::vector<ShaderPrint>> byLabel;
    glm::vec3 v3(uint32_t label, size_t i = 0) const {
        const ShaderPrint& p = byLabel.at(label).at(i);
        return {p.f(0), p.f(1), p.f(2)};
    }
    float f(uint32_t label) const { return byLabel.at(label).at(0).f(0); }
    uint32_t u(uint32_t label, int i = 0) const { return byLabel.at(label).at(0).u(i); }
    bool has(uint32_t label) const { return byLabel.count(label) != 0; }
};

Printed collect(const RenderRun& run) {
    Printed p;
    for (const ShaderPrint& s : frontFragment(run.frames.back().prints).prints)
        p.byLabel[s.label].push_back(s);
    return p;
}

// Relative error of a colour term, with a floor so near-black terms compare absolutely.
float relError(glm::vec3 gpu, glm::vec3 cpu) {
    glm::vec3 diff = glm::abs(gpu - cpu);
    float scale = std::max({cpu.x, cpu.y, cpu.z, 1e-3f});
    return std::max({diff.x, diff.y, diff.z}) / scale;
}

uint8_t tonemap(float hdr) { // shaders/post/tonemap.comp at 1x, exposure 1
    float x = std::max(hdr, 0.0f);
    float y = std::clamp((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
    float s = y < 0.0031308f ? y * 12.92f : 1.055f * std::pow(y, 1.0f / 2.4f) - 0.055f;
    return uint8_t(std::clamp(s, 0.0f, 1.0f) * 255.0f + 0.5f);
}

// Checks the printed material and light terms against the scene on the CPU (1%); returns the
// shaded colour the GPU printed.
glm::vec3 checkSurface(const Printed& p, const Scene& scene, const std::string& where) {
    uint32_t instance = p.u(PRINT_INSTANCE);
    EXPECT_LT(instance, scene.instances.size()) << where;
    if (instance >= scene.instances.size()) return glm::vec3(0.0f);
    const Material& mat = scene.materials[scene.meshes[scene.instances[instance].mesh].material];
    // Material values: the scene's factors (builtin:smooth has no textures).
    glm::vec3 base = p.v3(PRINT_BASE_COLOR);
    EXPECT_LT(relError(base, glm::vec3(mat.baseColorFactor)), 0.01f) << where << " " << mat.name;
    EXPECT_NEAR(p.f(PRINT_ROUGHNESS), std::clamp(mat.roughnessFactor, 0.0f, 1.0f), 0.01f) << where;
    EXPECT_NEAR(p.f(PRINT_METALLIC), mat.metallicFactor, 0.01f) << where;
    glm::vec3 n = p.v3(PRINT_SHADING_NORMAL);
    EXPECT_NEAR(glm::length(n), 1.0f, 1e-3f) << where;

    // Lights: the same BRDF on the CPU at the printed surface point.
    glm::vec3 pos = p.v3(PRINT_POSITION);
    const Camera& cam = scene.cameras.front();
    glm::vec3 v = glm::normalize(cam.position - pos);
    glm::vec3 sum = p.v3(PRINT_EMISSIVE) + p.v3(PRINT_AMBIENT);
    // Rendered without an environment, so that every light term has a CPU oracle here (the
    // environment's is judged by the furnace test, ImageBasedLighting): its term is zero.
    EXPECT_LT(glm::length(p.v3(PRINT_AMBIENT)), 1e-6f) << where;
    bool haveSun = false;
    size_t punctual = 0;
    for (const Light& l : scene.lights) {
        if (l.type == LightType::Directional && !haveSun) {
            haveSun = true;
            float shadow = p.f(PRINT_SUN_SHADOW); // the shadow map is the GPU's; the BRDF is not
            EXPECT_TRUE(shadow >= 0.0f && shadow <= 1.0f);
            glm::vec3 cpu = brdf(base, mat.metallicFactor, p.f(PRINT_ROUGHNESS), n, v,
                                 -glm::normalize(l.direction), l.color * l.intensity * shadow);
            EXPECT_LT(relError(p.v3(PRINT_SUN), cpu), 0.01f) << where << " sun";
            sum += p.v3(PRINT_SUN);
            continue;
        }
        glm::vec3 toLight = l.position - pos;
        float dist = glm::length(toLight);
        glm::vec3 cpu = brdf(base, mat.metallicFactor, p.f(PRINT_ROUGHNESS), n, v, toLight / dist,
                             l.color * l.intensity * rangeAttenuation(dist, l.range));
        const ShaderPrint& printed = p.byLabel.at(PRINT_LIGHT).at(punctual);
        EXPECT_EQ(printed.f(3), float(punctual));
        EXPECT_LT(relError(p.v3(PRINT_LIGHT, punctual), cpu), 0.01f) << where << " " << l.name;
        std::printf("[ figures ] %s light %s: gpu %.5f %.5f %.5f cpu %.5f %.5f %.5f\n",
                    where.c_str(), l.name.c_str(), p.v3(PRINT_LIGHT, punctual).x,
                    p.v3(PRINT_LIGHT, punctual).y, p.v3(PRINT_LIGHT, punctual).z, cpu.x, cpu.y,
                    cpu.z);
        sum += p.v3(PRINT_LIGHT, punctual);
        ++punctual;
    }
    EXPECT_EQ(p.byLabel.at(PRINT_LIGHT).size(), punctual);
    // The printed terms are shadeSurface's, taken apart: they add up to its result.
    glm::vec3 shaded = p.v3(PRINT_SHADED);
    EXPECT_LT(relError(sum, shaded), 0.01f) << where;
    return shaded;
}

RenderOptions inspectOptions(RenderMode mode, int32_t x, int32_t y) {
    RenderOptions o = renderOptions("builtin:smooth", mode, 160, 90);
    o.shadelsPerMetre = 32.0f; // one density, no chunks: instance i is the scene's instance i
    o.inspectX = x;
    o.inspectY = y;
    o.environment = "none";
    o.environmentGiven = true;
    return o;
}

} // namespace

TEST(Inspect, ForwardPixelAgreesWithTheCpuBrdfAndTheImage) {
    Scene scene = loadScene("builtin:smooth", {});
    // The gold sphere (metal), the red sphere and the ground.
    for (auto [x, y] : {std::pair{82, 44}, std::pair{52, 48}, std::pair{80, 80}}) {
        RenderRun run = renderChecked(inspectOptions(RenderMode::Forward, x, y));
        Printed p = collect(run);
        std::string where = "forward " + std::to_string(x) + "," + std::to_string(y);
        ASSERT_TRUE(p.has(PRINT_INSTANCE)) << where << ": nothing printed";
        EXPECT_EQ(p.u(PRINT_INSPECT_PIXEL, 0), uint32_t(x));
        EXPECT_EQ(p.u(PRINT_INSPECT_PIXEL, 1), uint32_t(y));
        EXPECT_EQ(p.byLabel.at(PRINT_INSTANCE).size(), 1u) << where; // the front fragment's
        glm::vec3 shaded = checkSurface(p, scene, where);
        // ... and is what the frame shows at that pixel.
        const uint8_t* px = &run.frames.back().rgba[(size_t(y) * 160 + x) * 4];
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(int(px[c]), int(tonemap(shaded[c])), 1) << where;
        EXPECT_TRUE(run.stats.contains("inspect"));
    }
    // A background pixel prints nothing.
    RenderRun sky = renderChecked(inspectOptions(RenderMode::Forward, 80, 2));
    EXPECT_TRUE(sky.frames.back().prints.empty());
}

// Raster reconstruction and the compute resolve of --marking visibility print the same things.
class InspectDecoupled : public ::testing::TestWithParam<MarkingMode> {};

TEST_P(InspectDecoupled, PixelPrintsItsChunkAndAgreesWithTheCpuBrdf) {
    Scene scene = loadScene("builtin:smooth", {});
    RenderOptions o = inspectOptions(RenderMode::Decoupled, 52, 48);
    o.marking = GetParam();
    std::string where =
        o.marking == MarkingMode::Raster ? "decoupled raster 52,48" : "decoupled visibility 52,48";
    RenderRun run = renderChecked(o);
    Printed p = collect(run);
    ASSERT_TRUE(p.has(PRINT_SHADEL_CHUNK)) << where;
    EXPECT_NE(p.u(PRINT_SHADEL_CHUNK, 2), 0xFFFFFFFFu); // the chunk got a storage slot
    const ShaderPrint& lod = p.byLabel.at(PRINT_SHADEL_LOD).at(0);
    EXPECT_TRUE(std::isfinite(lod.f(0)) && lod.f(0) >= 0.0f);
    EXPECT_EQ(p.u(PRINT_SHADEL_CHUNK, 3), uint32_t(lod.f(1))); // chunk of the first MIP
    // Why the LOD is what it is: the frame's shading bias and the object's material rate.
    ASSERT_TRUE(p.has(PRINT_SHADING_BIAS)) << where;
    const ShaderPrint& bias = p.byLabel.at(PRINT_SHADING_BIAS).at(0);
    EXPECT_FLOAT_EQ(bias.f(0), run.stats["shading_bias"].get<float>());
    EXPECT_GE(bias.f(1), 0.0f);
    EXPECT_LE(bias.f(1), 1.0f);
    glm::vec3 shaded = checkSurface(p, scene, where);
    glm::vec3 reconstructed = p.v3(PRINT_RECONSTRUCTED);
    glm::vec3 output = p.v3(PRINT_OUTPUT);
    EXPECT_LT(relError(output, reconstructed), 1e-4f); // no miss: the storage's value is shown
    // Shadels are shaded at shadel centres and filtered: close to, not equal to, the pixel's.
    std::printf("[ figures ] %s: reconstructed %.4f %.4f %.4f, at the pixel %.4f %.4f %.4f, "
                "lod %.2f\n",
                where.c_str(), reconstructed.x, reconstructed.y, reconstructed.z, shaded.x,
                shaded.y, shaded.z, lod.f(0));
    EXPECT_LT(relError(reconstructed, shaded), 0.1f);
    // The pixel the frame shows is the printed output.
    const uint8_t* px = &run.frames.back().rgba[(size_t(48) * 160 + 52) * 4];
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(int(px[c]), int(tonemap(output[c])), 1) << where;
}

INSTANTIATE_TEST_SUITE_P(Marking, InspectDecoupled,
                         ::testing::Values(MarkingMode::Raster, MarkingMode::Visibility),
                         [](const auto& info) {
                             return info.param == MarkingMode::Raster ? "Raster" : "Visibility";
                         });
