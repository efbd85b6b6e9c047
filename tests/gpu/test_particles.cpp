// GPU particles (render/particles, seed 004): the particle lightmap atlas against per-pixel
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

// builtin:particles with only its smoke column (the fire is unlit: identical in every lighting
// mode, it would only inflate a PSNR), rendered forward at w x h.
ParticleFrameImage renderSmoke(ParticleLighting lighting, bool particles, uint32_t w, uint32_t h) {
    Gpu& gpu = sharedGpu();
    uint32_t before = validationErrors();
    Scene scene = loadScene("builtin:particles");
    scene.emitters.erase(std::remove_if(scene.emitters.begin(), scene.emitters.end(),
                                        [](const ParticleEmitter& e) { return !e.lit; }),
                         scene.emitters.end());
    EXPECT_EQ(scene.emitters.size(), 1u);
    GpuScene gs;
    uploadScene(gpu, scene, gs);
    RenderSettings s;
    s.width = w;
    s.height = h;
    s.shadowMapSize = 512;
    s.particles = particles;
    s.particleLighting = lighting;
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

TEST(Particles, SimulationIsReproducibleAndMoves) {
    RenderOptions o = renderOptions("builtin:particles", RenderMode::Forward, 160, 90);
    o.frames = 3;
    RenderRun a = renderChecked(o);
    RenderRun b = renderChecked(o);
    ASSERT_EQ(a.frames.size(), 3u);
    for (size_t f = 0; f < 3; ++f) EXPECT_EQ(a.frames[f].rgba, b.frames[f].rgba) << "frame " << f;
    EXPECT_NE(a.frames[0].rgba, a.frames[2].rgba) << "the particles should move between frames";
    const auto& p = a.stats["particles"];
    EXPECT_EQ(p["particles"].get<uint32_t>(), 96u + 64u);
    EXPECT_NEAR(p["simulated_seconds"].get<double>(), 4.8 + 3.0 / 60.0, 0.05);
    // Passes of the frame, in order.
    std::vector<std::string> names;
    for (const auto& pass : a.stats["passes"]) names.push_back(pass["name"]);
    auto at = [&](const char* n) {
        return std::find(names.begin(), names.end(), n) - names.begin();
    };
    EXPECT_LT(at("particleSimulate"), at("particleAtlasLighting"));
    EXPECT_LT(at("particleAtlasLighting"), at("oitAccumulate"));
    EXPECT_LT(at("oitAccumulate"), at("particleSprites"));
    EXPECT_LT(at("particleSprites"), at("oitComposite"));
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
