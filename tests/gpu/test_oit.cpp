// Transparency (render/oit): weighted blended OIT with additiveness against its limits and
// against the CPU-sorted reference.
#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "gpu_test_env.h"

#include "render/oit/oit.h"
#include "render/post/tone_curve.h"
#include "scene/mesh_utils.h"

using namespace shadel;
using namespace shadel::test;

namespace {

constexpr uint32_t kW = 192, kH = 108;

RenderRun renderTransparency(RenderMode mode, OitMode oit, std::optional<uint64_t> shuffle = {},
                             MarkingMode marking = MarkingMode::Auto) {
    RenderOptions o = renderOptions("builtin:transparency", mode, kW, kH);
    o.oit = oit;
    o.marking = marking;
    o.shuffleDraws = shuffle.has_value();
    o.shuffleSeed = shuffle.value_or(0);
    return renderChecked(o);
}

// ---- The synthetic case: full-screen layers of known colour in front of a known sky --------

struct Layer {
    float depth;       // metres in front of the camera
    glm::vec3 emitted; // the layer's only light: black base colour, no lights, no ambient
    float alpha;
    float additiveness;
};

const glm::vec3 kSky{0.2f, 0.3f, 0.4f};

Scene layeredScene(const std::vector<Layer>& layers) {
    Scene scene;
    scene.name = "layers";
    scene.skyColor = kSky;
    scene.ambientColor = glm::vec3(0.0f);
    for (size_t i = 0; i < layers.size(); ++i) {
        Material m;
        m.name = "layer " + std::to_string(i);
        m.baseColorFactor = glm::vec4(0.0f, 0.0f, 0.0f, layers[i].alpha);
        m.emissiveFactor = layers[i].emitted;
        m.alphaMode = AlphaMode::Blend;
        m.additiveness = layers[i].additiveness;
        m.doubleSided = true;
        scene.materials.push_back(m);
        Mesh quad = makePlane(m.name, 40.0f, 40.0f, uint32_t(i)); // faces +Y
        scene.meshes.push_back(quad);
        Instance inst;
        inst.name = m.name;
        inst.mesh = uint32_t(i);
        inst.transform = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -layers[i].depth)) *
                         glm::rotate(glm::mat4(1.0f), glm::radians(90.0f), glm::vec3(1, 0, 0));
        scene.instances.push_back(inst);
    }
    Camera c;
    c.name = "front";
    c.position = glm::vec3(0.0f);
    c.forward = glm::vec3(0, 0, -1);
    c.znear = 0.1f;
    c.zfar = 100.0f;
    scene.cameras.push_back(c);
    return scene;
}

// The centre pixel (RGB8) of the synthetic scene rendered forward with `mode`.
glm::ivec3 renderCentre(const std::vector<Layer>& layers, OitMode mode) {
    Gpu& gpu = sharedGpu();
    uint32_t before = validationErrors();
    Scene scene = layeredScene(layers);
    GpuScene gs;
    uploadScene(gpu, scene, gs);
    RenderSettings s;
    s.width = 32;
    s.height = 18;
    s.shadowMapSize = 64;
    s.oit = mode;
    // The layers' only light is their emission: no environment, and behind them kSky's radiance
    // (the solid background the display shows as kSky's display colour).
    s.environment = "none";
    s.environmentGiven = true;
    s.backgroundEnvironment = false;
    s.backgroundColor = displayColor(kSky, 1.0f, Tonemap::AcesNarkowicz);
    Renderer r;
    initRenderer(r, gpu, s, gs);
    FrameResult f = renderFrame(r, gs, makeCameraView(scene.cameras[0], s.width, s.height));
    EXPECT_EQ(f.transparentDraws, layers.size());
    EXPECT_EQ(f.shaderAsserts, 0u);
    destroyRenderer(r);
    destroyScene(gpu, gs);
    EXPECT_EQ(validationErrors(), before);
    size_t i = (size_t(s.height / 2) * s.width + s.width / 2) * 4;
    return {f.rgba[i], f.rgba[i + 1], f.rgba[i + 2]};
}

// The display transform of shaders/post/tonemap.comp (exposure 1), written out again.
glm::ivec3 display(glm::vec3 hdr) {
    glm::ivec3 out;
    for (int c = 0; c < 3; ++c) {
        double x = std::max(double(hdr[c]), 0.0);
        double y = std::clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
        double s = y < 0.0031308 ? y * 12.92 : 1.055 * std::pow(y, 1.0 / 2.4) - 0.055;
        out[c] = int(std::clamp(s, 0.0, 1.0) * 255.0 + 0.5);
    }
    return out;
}

// The weight of shaders/oit/wboit.glsl, written out again: min(1e4 b^3 + 5, 300) a^3 with
// b = 1 - canonical depth over [0.5, 300] m and a = min(3 coverage, 1).
double weight(double coverage, double depth) {
    const double n = 0.5, f = 300.0;
    double canonical = std::clamp(f / (f - n) - f * n / (depth * (f - n)), 0.0, 1.0);
    double b = 1.0 - canonical, a = std::min(3.0 * coverage, 1.0);
    return std::min(1e4 * b * b * b + 5.0, 300.0) * a * a * a;
}

void expectNear(glm::ivec3 got, glm::ivec3 want, const char* what) {
    for (int c = 0; c < 3; ++c)
        EXPECT_LE(std::abs(got[c] - want[c]), 1)
            << what << ": channel " << c << " got " << got[c] << " want " << want[c];
}

} // namespace

TEST(Oit, ShuffledDrawOrderChangesNothingVisible) {
    RenderRun base = renderTransparency(RenderMode::Forward, OitMode::Wboit);
    uint32_t draws = base.stats["transparent_draws"].get<uint32_t>();
    ASSERT_GE(draws, 15u) << "the camera should see the panes, sphere, smoke and fire";
    for (uint64_t seed : {1u, 77u}) {
        std::vector<uint32_t> order = shuffledOrder(draws, seed);
        ASSERT_FALSE(std::is_sorted(order.begin(), order.end())) << "seed " << seed;
        RenderRun shuffled = renderTransparency(RenderMode::Forward, OitMode::Wboit, seed);
        double p = psnr(base.frames[0].rgba, shuffled.frames[0].rgba);
        RecordProperty("psnr_seed_" + std::to_string(seed), std::to_string(p));
        EXPECT_GE(p, 50.0) << "--shuffle-draws " << seed;
    }
}

TEST(Oit, WboitMatchesSortedReferenceForward) {
    RenderRun wboit = renderTransparency(RenderMode::Forward, OitMode::Wboit);
    RenderRun sorted = renderTransparency(RenderMode::Forward, OitMode::Sorted);
    std::vector<std::string> passes;
    for (auto& p : wboit.stats["passes"]) passes.push_back(p["name"]);
    EXPECT_NE(std::find(passes.begin(), passes.end(), "oitComposite"), passes.end());
    double p = psnr(wboit.frames[0].rgba, sorted.frames[0].rgba);
    RecordProperty("psnr", std::to_string(p));
    std::printf("forward WBOIT vs sorted at %ux%u: %.2f dB\n", kW, kH, p);
    EXPECT_GE(p, 30.0);
    EXPECT_LT(p, 99.0) << "WBOIT is an approximation: identical images mean one path ran twice";
    // Sorting is order dependent by construction; shuffling must not reach it.
    RenderRun sortedShuffled = renderTransparency(RenderMode::Forward, OitMode::Sorted, 5);
    EXPECT_EQ(sorted.frames[0].rgba, sortedShuffled.frames[0].rgba);
}

TEST(Oit, WboitMatchesSortedReferenceDecoupled) {
    RenderRun wboit = renderTransparency(RenderMode::Decoupled, OitMode::Wboit);
    RenderRun sorted = renderTransparency(RenderMode::Decoupled, OitMode::Sorted);
    double p = psnr(wboit.frames[0].rgba, sorted.frames[0].rgba);
    RecordProperty("psnr", std::to_string(p));
    std::printf("decoupled WBOIT vs sorted at %ux%u: %.2f dB\n", kW, kH, p);
    EXPECT_GE(p, 30.0);
    EXPECT_EQ(wboit.stats["reconstruction_misses"].get<uint64_t>(), 0u);
}

// Decoupled transparency: the blended instances are shaded in shadel space (marked against the
// opaque depth only) and reconstructed into the WBOIT targets, with no misses. Both marking
// paths: with the visibility buffer (nearest surface only) a raster pass marks the layers.
TEST(Oit, DecoupledTransparencyMatchesForward) {
    RenderRun forward = renderTransparency(RenderMode::Forward, OitMode::Wboit);
    for (MarkingMode marking : {MarkingMode::Raster, MarkingMode::Visibility}) {
        const char* name = marking == MarkingMode::Raster ? "raster" : "visibility";
        RenderRun decoupled =
            renderTransparency(RenderMode::Decoupled, OitMode::Wboit, {}, marking);
        const auto& s = decoupled.stats;
        EXPECT_EQ(s["marking"], name);
        EXPECT_GE(s["transparent_draws_decoupled"].get<uint32_t>(), 15u)
            << name << ": panes, sphere, smoke and fire should be shaded in shadel space";
        EXPECT_EQ(s["reconstruction_misses"].get<uint64_t>(), 0u) << name;
        double p = psnr(forward.frames[0].rgba, decoupled.frames[0].rgba);
        RecordProperty(std::string("psnr_") + name, std::to_string(p));
        std::printf("decoupled (%s marking) vs forward (both WBOIT) at %ux%u: %.2f dB\n", name, kW,
                    kH, p);
        EXPECT_GE(p, 35.0) << name;
    }
}

// Additiveness 1: the layers add to what is behind them. WBOIT gets the sum as the weighted
// mean colour times the additive coverage, so it is exact where the layers weigh the same
// (here: both nearer than 1.6 m, where the depth term is capped at 300, and coverage >= 1/3);
// with unequal weights the nearer layer's hue dominates (colour dominance).
TEST(Oit, AdditivenessOneIsAdditiveBlending) {
    std::vector<Layer> layers = {{1.0f, {0.30f, 0.10f, 0.05f}, 1.0f, 1.0f},
                                 {1.5f, {0.05f, 0.20f, 0.10f}, 0.8f, 1.0f}};
    ASSERT_EQ(weight(layers[0].alpha, layers[0].depth), weight(layers[1].alpha, layers[1].depth));
    glm::vec3 sum =
        kSky + layers[0].emitted * layers[0].alpha + layers[1].emitted * layers[1].alpha;
    expectNear(renderCentre(layers, OitMode::Wboit), display(sum), "wboit, additive");
    expectNear(renderCentre(layers, OitMode::Sorted), display(sum), "sorted, additive");
}

// Additiveness 0: McGuire's WBOIT, C (1 - R) + D R with C the coverage-weighted mean colour;
// the sorted reference composites exactly ("over"), and the two differ here.
TEST(Oit, AdditivenessZeroIsWboitAlpha) {
    std::vector<Layer> layers = {{1.0f, {0.8f, 0.2f, 0.1f}, 0.5f, 0.0f},
                                 {3.0f, {0.1f, 0.3f, 0.9f}, 0.2f, 0.0f}};
    double sumW = 0.0;
    glm::dvec3 sumC(0.0);
    double revealage = 1.0;
    for (const Layer& l : layers) {
        double w = weight(l.alpha, l.depth);
        sumC += glm::dvec3(l.emitted) * double(l.alpha) * w; // premultiplied colour * w
        sumW += double(l.alpha) * w;
        revealage *= 1.0 - l.alpha;
    }
    glm::vec3 wboit = glm::vec3(sumC / sumW * (1.0 - revealage) + glm::dvec3(kSky) * revealage);
    glm::vec3 over = layers[0].emitted * layers[0].alpha +
                     (1.0f - layers[0].alpha) *
                         (layers[1].emitted * layers[1].alpha + (1.0f - layers[1].alpha) * kSky);
    ASSERT_NE(display(wboit), display(over)) << "the synthetic case must tell the two apart";
    expectNear(renderCentre(layers, OitMode::Wboit), display(wboit), "wboit, alpha");
    expectNear(renderCentre(layers, OitMode::Sorted), display(over), "sorted, alpha");
}

// A half-additive layer: opacity alpha (1 - k), colour still alpha * colour.
TEST(Oit, HalfAdditiveLayerOverSky) {
    std::vector<Layer> layers = {{2.0f, {0.6f, 0.4f, 0.2f}, 0.8f, 0.5f}};
    float opacity = 0.8f * 0.5f;
    glm::vec3 want = layers[0].emitted * 0.8f + kSky * (1.0f - opacity);
    expectNear(renderCentre(layers, OitMode::Wboit), display(want), "wboit, half additive");
    expectNear(renderCentre(layers, OitMode::Sorted), display(want), "sorted, half additive");
}
