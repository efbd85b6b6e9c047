// GPU particles (render/particles): the particle lightmap atlas against per-pixel
// lighting on the smoke, reproducible simulation, LOD from screen size, CLI input.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sys/wait.h>

#include "gpu_test_env.h"
#include "render/particles/particles.h"
#include "scene/load.h"

using namespace shadel;
using namespace shadel::test;

namespace {

struct ParticleFrameImage {
    std::vector<uint8_t> rgba;
    ParticleStats stats;
};

// builtin:particles with its emitters edited by `edit`, rendered forward at w x h.
template <typename Edit>
ParticleFrameImage renderEmitters(Edit edit, ParticleLighting lighting, bool particles, uint32_t w,
                                  uint32_t h, bool halfRes = true) {
    Gpu& gpu = sharedGpu();
    uint32_t before = validationErrors();
    Scene scene = loadScene("builtin:particles");
    edit(scene.emitters);
    GpuScene gs;
    uploadScene(gpu, scene, gs);
    RenderSettings s;
    s.width = w;
    s.height = h;
    s.shadowMapSize = 512;
    s.particles = particles;
    s.particleLighting = lighting;
    s.particleHalfRes = halfRes;
    Renderer r;
    initRenderer(r, gpu, s, gs);
    FrameResult f = renderFrame(r, gs, makeCameraView(scene.cameras[0], s.width, s.height));
    EXPECT_EQ(f.shaderAsserts, 0u);
    ParticleFrameImage out{f.rgba, readParticleStats(r)};
    destroyRenderer(r);
    destroyScene(gpu, gs);
    EXPECT_EQ(validationErrors(), before);
    return out;
}

// Only the smoke column (the fire is unlit and the debris lit per vertex in every mode: they
// would only inflate a PSNR).
ParticleFrameImage renderSmoke(ParticleLighting lighting, bool particles, uint32_t w, uint32_t h,
                               bool halfRes = true) {
    auto smokeOnly = [](std::vector<ParticleEmitter>& emitters) {
        std::erase_if(emitters, [](const ParticleEmitter& e) { return !e.lit || e.mesh; });
        EXPECT_EQ(emitters.size(), 1u);
    };
    return renderEmitters(smokeOnly, lighting, particles, w, h, halfRes);
}

// PSNR over the pixels the smoke changes (against the image without particles).
double smokePsnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b,
                 const std::vector<uint8_t>& background, size_t* pixels) {
    double se = 0;
    size_t n = 0;
    *pixels = 0;
    for (size_t i = 0; i + 3 < a.size(); i += 4) {
        bool smoke = false;
        for (int c = 0; c < 3; ++c)
            smoke = smoke || std::abs(int(a[i + c]) - int(background[i + c])) > 2 ||
                    std::abs(int(b[i + c]) - int(background[i + c])) > 2;
        if (!smoke) continue;
        ++*pixels;
        for (int c = 0; c < 3; ++c, ++n) {
            double d = double(a[i + c]) - double(b[i + c]);
            se += d * d;
        }
    }
    double mse = se / double(std::max<size_t>(n, 1));
    return mse == 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

} // namespace

TEST(Particles, AtlasLightingMatchesPerPixelOnTheSmoke) {
    const uint32_t w = 320, h = 180;
    ParticleFrameImage none = renderSmoke(ParticleLighting::Pixel, false, w, h);
    ParticleFrameImage pixel = renderSmoke(ParticleLighting::Pixel, true, w, h);
    ParticleFrameImage atlas = renderSmoke(ParticleLighting::Atlas, true, w, h);
    ParticleFrameImage vertex = renderSmoke(ParticleLighting::Vertex, true, w, h);
    size_t smokePixels = 0, vertexPixels = 0;
    double atlasDb = smokePsnr(atlas.rgba, pixel.rgba, none.rgba, &smokePixels);
    double vertexDb = smokePsnr(vertex.rgba, pixel.rgba, none.rgba, &vertexPixels);
    std::printf("smoke at %ux%u: %zu pixels; atlas vs pixel %.2f dB, vertex vs pixel %.2f dB; "
                "%u sprites in the atlas, %u texels\n",
                w, h, smokePixels, atlasDb, vertexDb, atlas.stats.atlasSprites,
                atlas.stats.atlasTexels);
    EXPECT_GT(smokePixels, size_t(w) * h / 20) << "the smoke should cover part of the view";
    EXPECT_GE(atlasDb, 32.0);
    // Only the atlas mode asks for rectangles; every visible lit sprite got one that fits.
    EXPECT_EQ(pixel.stats.atlasSprites, 0u);
    EXPECT_GT(atlas.stats.atlasSprites, 20u);
    EXPECT_EQ(atlas.stats.atlasOverflowed, 0u);
    EXPECT_GT(atlas.stats.atlasTexels, 0u);
    // The atlas carries the normal map's detail that per-vertex lighting cannot.
    EXPECT_GT(atlasDb, vertexDb);
}

// Seed 001's low-resolution particles: sprites accumulated at half resolution in their own
// WBOIT targets and combined with the surfaces' in the composite look like the full-resolution
// sprites (the smoke is soft), and are really drawn at half resolution (not identical).
TEST(Particles, HalfResolutionSpritesMatchFullResolution) {
    const uint32_t w = 320, h = 180;
    ParticleFrameImage none = renderSmoke(ParticleLighting::Atlas, false, w, h);
    ParticleFrameImage full = renderSmoke(ParticleLighting::Atlas, true, w, h, false);
    ParticleFrameImage half = renderSmoke(ParticleLighting::Atlas, true, w, h, true);
    size_t smokePixels = 0;
    double smokeDb = smokePsnr(half.rgba, full.rgba, none.rgba, &smokePixels);
    auto all = [](std::vector<ParticleEmitter>&) {};
    ParticleFrameImage allFull = renderEmitters(all, ParticleLighting::Atlas, true, w, h, false);
    ParticleFrameImage allHalf = renderEmitters(all, ParticleLighting::Atlas, true, w, h, true);
    double frameDb = psnr(allHalf.rgba, allFull.rgba);
    std::printf("[ figures ] particles %ux%u, half vs full resolution: smoke %.2f dB over %zu "
                "pixels, whole frame (smoke, fire, debris) %.2f dB\n",
                w, h, smokeDb, smokePixels, frameDb);
    EXPECT_NE(half.rgba, full.rgba);
    EXPECT_GT(smokePixels, size_t(w) * h / 20);
    EXPECT_GE(smokeDb, 30.0);
    EXPECT_GE(frameDb, 35.0);
}

TEST(Particles, SimulationIsReproducibleAndMoves) {
    RenderOptions o = renderOptions("builtin:particles", RenderMode::Forward, 160, 90);
    o.frames = 3;
    RenderRun a = renderChecked(o);
    RenderRun b = renderChecked(o);
    ASSERT_EQ(a.frames.size(), 3u);
    for (size_t f = 0; f < 3; ++f) EXPECT_EQ(a.frames[f].rgba, b.frames[f].rgba) << "frame " << f;
    EXPECT_NE(a.frames[0].rgba, a.frames[2].rgba) << "the particles should move between frames";
    const auto& p = a.stats["particles"];
    EXPECT_EQ(p["particles"].get<uint32_t>(), 96u + 64u + 24u); // smoke, fire, debris
    EXPECT_NEAR(p["simulated_seconds"].get<double>(), 4.8 + 3.0 / 60.0, 0.05);
    // Passes of the frame, in order.
    std::vector<std::string> names;
    for (const auto& pass : a.stats["passes"]) names.push_back(pass["name"]);
    auto at = [&](const char* n) {
        return std::find(names.begin(), names.end(), n) - names.begin();
    };
    EXPECT_LT(at("forwardShading"), at("particleSimulate"));
    EXPECT_LT(at("particleSimulate"), at("particleMeshes"));
    EXPECT_LT(at("particleMeshes"), at("particleAtlasLighting"));
    EXPECT_LT(at("particleAtlasLighting"), at("oitAccumulate"));
    EXPECT_LT(at("oitAccumulate"), at("particleSpritesHalf")); // --particle-resolution half
    EXPECT_LT(at("particleSpritesHalf"), at("oitComposite"));
    EXPECT_LT(at("oitComposite"), int(names.size()));
}

TEST(Particles, AtlasLodFollowsScreenSize) {
    auto meanSide = [](const RenderRun& run) {
        const auto& perLod = run.stats["particles"]["atlas_sprites_per_lod"];
        double texels = 0, sprites = 0;
        for (uint32_t l = 0; l < PARTICLE_ATLAS_LODS; ++l) {
            double n = perLod[l].get<double>();
            texels += n * gpu::particleAtlasSide(l);
            sprites += n;
        }
        return sprites > 0 ? texels / sprites : 0.0;
    };
    RenderOptions o = renderOptions("builtin:particles", RenderMode::Forward, 160, 90);
    RenderRun nearRun = renderChecked(o);
    o.camera = "far";
    RenderRun farRun = renderChecked(o);
    double nearSide = meanSide(nearRun), farSide = meanSide(farRun);
    std::printf("mean atlas side: main camera %.1f, far camera %.1f texels\n", nearSide, farSide);
    EXPECT_GT(nearSide, 0.0);
    EXPECT_GT(farSide, 0.0);
    EXPECT_LT(farSide, nearSide * 0.75) << "farther sprites should take smaller rectangles";
    EXPECT_LE(nearSide, 32.0) << "the default bias caps sprites at 32x32";
}

// Mesh particles take the forward path: opaque boxes, lit per vertex or per pixel with wrap
// shading. Wrap lights the faces turned from the lights, so it brightens the debris.
TEST(Particles, MeshParticlesAreLitWithWrapPerVertexOrPixel) {
    const uint32_t w = 320, h = 180;
    auto debris = [](bool vertexLit, float wrap) {
        return [=](std::vector<ParticleEmitter>& emitters) {
            std::erase_if(emitters, [](const ParticleEmitter& e) { return !e.mesh; });
            ASSERT_EQ(emitters.size(), 1u);
            emitters[0].vertexLit = vertexLit;
            emitters[0].wrap = wrap;
        };
    };
    ParticleFrameImage none =
        renderEmitters(debris(true, 0.5f), ParticleLighting::Atlas, false, w, h);
    ParticleFrameImage vertex =
        renderEmitters(debris(true, 0.5f), ParticleLighting::Atlas, true, w, h);
    ParticleFrameImage pixel =
        renderEmitters(debris(false, 0.5f), ParticleLighting::Atlas, true, w, h);
    ParticleFrameImage lambert =
        renderEmitters(debris(false, 0.0f), ParticleLighting::Atlas, true, w, h);
    size_t pixels = 0;
    double db = smokePsnr(vertex.rgba, pixel.rgba, none.rgba, &pixels);
    // Mean brightness over the debris pixels (those the particles change).
    auto mean = [&](const std::vector<uint8_t>& img) {
        double sum = 0;
        size_t n = 0;
        for (size_t i = 0; i + 3 < img.size(); i += 4) {
            bool debrisPixel = false;
            for (int c = 0; c < 3; ++c)
                debrisPixel =
                    debrisPixel || std::abs(int(pixel.rgba[i + c]) - int(none.rgba[i + c])) > 2;
            if (!debrisPixel) continue;
            sum += img[i] + img[i + 1] + img[i + 2];
            ++n;
        }
        return n ? sum / double(3 * n) : 0.0;
    };
    std::printf("debris at %ux%u: %zu pixels; per vertex vs per pixel %.2f dB; mean wrap 0.5 %.1f, "
                "Lambert %.1f\n",
                w, h, pixels, db, mean(pixel.rgba), mean(lambert.rgba));
    EXPECT_GT(pixels, 50u) << "the debris should be on screen";
    EXPECT_EQ(vertex.stats.atlasSprites, 0u) << "mesh particles take no atlas rectangles";
    EXPECT_GE(db, 25.0) << "flat faces: per-vertex lighting stays close to per-pixel";
    EXPECT_GT(mean(pixel.rgba), mean(lambert.rgba) + 1.0);
}

TEST(Particles, BadParticleFlagsExitWith2) {
    for (const std::string args :
         {"render --size 16x16 --particle-lighting sideways",
          "render --size 16x16 --particles maybe", "render --size 16x16 --particle-atlas-size 4",
          "render --size 16x16 --visualize atlas"}) {
        std::string errFile =
            (std::filesystem::temp_directory_path() / "shadel_particles_stderr.txt").string();
        std::string cmd =
            std::string("timeout 120 ") + SHADEL_BINARY + " " + args + " >/dev/null 2>" + errFile;
        int status = std::system(cmd.c_str());
        EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 2) << args;
    }
}
