// Environment maps (render/environment): the equirectangular convention against the Khronos
// glTF Sample Viewer's, the hemisphere against the ambient formula it replaces, the prefilter's
// furnace and energy, the BRDF table against direct quadrature.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "core/worker_pool.h"
#include "render/environment/equirect.h"
#include "render/environment/hemisphere.h"
#include "render/environment/prefilter.h"

namespace shadel {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The Sample Viewer's lookup, step by step: the world direction is turned by its
// environmentRotation (gl-matrix rotateY), the cube map is read there, and the cube map's
// texel at direction c was filled from the panorama at dirToUV(c.x, -c.y, c.z): its
// panorama_to_cubemap shader computes each face's directions with +t up while GL cube faces
// run t down, so y comes out negated. dirToUV is (0.5 + atan(z, x) / 2pi, 1 - acos(y) / pi),
// and the panorama is uploaded without a flip, so t = 0 is the file's first (top) row.
glm::dvec2 sampleViewerUv(glm::dvec3 d, double rotationDegrees) {
    double a = rotationDegrees * kPi / 180.0;
    glm::dvec3 c(std::cos(a) * d.x + std::sin(a) * d.z, d.y,
                 -std::sin(a) * d.x + std::cos(a) * d.z);
    glm::dvec3 p(c.x, -c.y, c.z);
    double u = 0.5 + 0.5 * std::atan2(p.z, p.x) / kPi;
    double t = 1.0 - std::acos(std::clamp(p.y, -1.0, 1.0)) / kPi;
    return {u - std::floor(u), t};
}

double wrappedDistance(double a, double b) {
    double d = std::abs(a - b);
    return std::min(d, 1.0 - d);
}

TEST(EnvironmentEquirect, MatchesTheSampleViewerOnTheSixAxes) {
    const glm::vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (float rotation : {0.0f, 30.0f, -75.0f})
        for (glm::vec3 axis : axes) {
            glm::vec2 ours = equirectUv(rotateToEnvironment(axis, rotation));
            glm::dvec2 theirs = sampleViewerUv(
                glm::dvec3(axis), double(kSampleViewerRotationOffsetDegrees) + rotation);
            EXPECT_NEAR(ours.y, theirs.y, 1e-6) << "axis " << axis.x << axis.y << axis.z;
            if (std::abs(axis.y) < 0.5f) { // u is undefined at the poles
                EXPECT_LT(wrappedDistance(ours.x, theirs.x), 1e-6)
                    << "axis " << axis.x << "," << axis.y << "," << axis.z << " rotation "
                    << rotation << ": u " << ours.x << " vs " << theirs.x;
            }
        }
    // Spelled out at rotation 0: up is the top row, +Z the middle column, +X a quarter in.
    EXPECT_NEAR(equirectUv({0, 1, 0}).y, 0.0f, 1e-6);
    EXPECT_NEAR(equirectUv({0, -1, 0}).y, 1.0f, 1e-6);
    EXPECT_NEAR(equirectUv({0, 0, 1}).x, 0.5f, 1e-6);
    EXPECT_NEAR(equirectUv({1, 0, 0}).x, 0.25f, 1e-6);
    EXPECT_NEAR(equirectUv({-1, 0, 0}).x, 0.75f, 1e-6);
    EXPECT_LT(wrappedDistance(equirectUv({0, 0, -1}).x, 0.0), 1e-6);
}

TEST(EnvironmentEquirect, DirectionsRoundTripAndRandomOnesMatchTheSampleViewer) {
    std::mt19937 rng(7);
    std::normal_distribution<float> n;
    double worst = 0.0;
    for (int i = 0; i < 2000; ++i) {
        glm::vec3 d = glm::normalize(glm::vec3(n(rng), n(rng), n(rng)));
        worst = std::max(worst, double(glm::length(equirectDirection(equirectUv(d)) - d)));
        glm::dvec2 sv = sampleViewerUv(glm::dvec3(d), 90.0);
        glm::vec2 uv = equirectUv(d);
        ASSERT_LT(wrappedDistance(uv.x, sv.x), 1e-5);
        ASSERT_NEAR(uv.y, sv.y, 1e-5);
    }
    EXPECT_LT(worst, 1e-5) << "largest round-trip error " << worst;
}

TEST(EnvironmentHemisphere, IrradianceReproducesTheAmbientFormula) {
    WorkerPool pool(2);
    struct Case {
        glm::vec3 sky, ambient;
        double tolerance; // measured: 0.00127 and 0.132
    };
    // The default colours (radiance positive everywhere) and a black ambient under a night sky
    // (builtin_lights: the radiance below is clamped and refitted).
    const Case cases[] = {{{0.55f, 0.7f, 0.95f}, {0.08f, 0.09f, 0.11f}, 0.0014},
                          {{0.01f, 0.012f, 0.02f}, {0.0f, 0.0f, 0.0f}, 0.145}};
    for (const Case& c : cases) {
        EquirectImage source = hemisphereRadiance(c.sky, c.ambient, 64, 32);
        EquirectImage irradiance = prefilterIrradiance(source, 64, pool);
        double worst = 0.0;
        glm::vec3 top = hemisphereAmbient(c.sky, c.ambient, 1.0f);
        for (int i = 0; i <= 20; ++i) {
            float ny = -1.0f + 0.1f * float(i);
            glm::vec3 d(std::sqrt(std::max(0.0f, 1.0f - ny * ny)), ny, 0.0f);
            glm::vec3 got = sampleEquirect(irradiance, d);
            glm::vec3 want = hemisphereAmbient(c.sky, c.ambient, ny);
            for (int k = 0; k < 3; ++k)
                worst = std::max(worst, double(std::abs(got[k] - want[k]) / top[k]));
        }
        EXPECT_LT(worst, c.tolerance) << "largest error relative to the zenith value: " << worst;
    }
}

TEST(EnvironmentPrefilter, UniformEnvironmentComesBackUnchangedAtEveryLevel) {
    WorkerPool pool(2);
    const glm::vec3 radiance(0.7f, 1.3f, 2.0f);
    PrefilterSettings s;
    s.specularWidth = 128, s.specularLevels = 6, s.specularSamples = 64;
    std::vector<EquirectImage> levels = prefilterSpecular(makeEquirect(96, 48, radiance), s, pool);
    ASSERT_EQ(levels.size(), 6u);
    double worst = 0.0;
    for (size_t l = 0; l < levels.size(); ++l) {
        EXPECT_EQ(levels[l].width, 128u >> l);
        for (const glm::vec3& t : levels[l].texels)
            for (int k = 0; k < 3; ++k)
                worst = std::max(worst, double(std::abs(t[k] / radiance[k] - 1.0f)));
    }
    EquirectImage irradiance = prefilterIrradiance(levels[0], 64, pool);
    for (const glm::vec3& t : irradiance.texels)
        for (int k = 0; k < 3; ++k)
            worst = std::max(worst, double(std::abs(t[k] / radiance[k] - 1.0f)));
    EXPECT_LT(worst, 0.01) << "largest relative error " << worst;
}

TEST(EnvironmentPrefilter, OneBrightTexelKeepsItsEnergyAtEveryLevel) {
    WorkerPool pool(2);
    PrefilterSettings s;
    s.specularWidth = 128, s.specularLevels = 6, s.specularSamples = 256; // the default count
    for (uint32_t row : {20u, 40u, 8u}) {
        EquirectImage source = makeEquirect(128, 64, glm::vec3(0.0f));
        source.at(37, row) = glm::vec3(1000.0f);
        double energy = equirectEnergy(source).x;
        std::vector<EquirectImage> levels = prefilterSpecular(source, s, pool);
        for (size_t l = 0; l < levels.size(); ++l) {
            double ratio = equirectEnergy(levels[l]).x / energy;
            // Measured: within 0.0111 (row 8, level 1).
            EXPECT_NEAR(ratio, 1.0, 0.012) << "row " << row << " level " << l;
        }
        double diffuse = equirectEnergy(prefilterIrradiance(levels[0], 64, pool)).x / energy;
        EXPECT_NEAR(diffuse, 1.0, 0.0005) << "row " << row << " irradiance (measured 0.00042)";
    }
}

// The sheen chain: a uniform environment comes back unchanged at every level, the thinnest lobes
// (most of whose reflected directions lie below the horizon) included.
TEST(EnvironmentPrefilter, SheenChainKeepsAUniformEnvironment) {
    WorkerPool pool(2);
    const glm::vec3 radiance(0.7f, 1.3f, 2.0f);
    PrefilterSettings s;
    s.sheenWidth = 64, s.sheenLevels = 6, s.specularSamples = 64;
    std::vector<EquirectImage> levels = prefilterSheen(makeEquirect(96, 48, radiance), s, pool);
    ASSERT_EQ(levels.size(), 6u);
    double worst = 0.0;
    for (size_t l = 0; l < levels.size(); ++l) {
        EXPECT_EQ(levels[l].width, std::max(64u >> l, 2u));
        for (const glm::vec3& t : levels[l].texels)
            for (int k = 0; k < 3; ++k)
                worst = std::max(worst, double(std::abs(t[k] / radiance[k] - 1.0f)));
    }
    EXPECT_LT(worst, 0.01) << "largest relative error " << worst;
}

// The Charlie lobe is wider than GGX's at the same roughness: under a sky bright only above the
// horizon, a texel looking at the horizon sees more of the bright half through the sheen chain
// than a sharp GGX level does, and the zenith stays brighter than the nadir.
TEST(EnvironmentPrefilter, SheenChainSpreadsLightFartherThanGgx) {
    WorkerPool pool(2);
    EquirectImage source = makeEquirect(128, 64, glm::vec3(0.0f));
    for (uint32_t y = 0; y < 32; ++y)
        for (uint32_t x = 0; x < 128; ++x) source.at(x, y) = glm::vec3(1.0f);
    PrefilterSettings s;
    s.specularWidth = 64, s.sheenWidth = 64, s.specularLevels = 5, s.sheenLevels = 5;
    s.specularSamples = 256;
    std::vector<EquirectImage> sheen = prefilterSheen(source, s, pool);
    std::vector<EquirectImage> ggx = prefilterSpecular(source, s, pool);
    const uint32_t level = 2; // roughness 0.5
    const EquirectImage& c = sheen[level];
    const EquirectImage& g = ggx[level];
    // Row 0's texels look 11 degrees off the zenith: the widest lobes reach that far below the
    // horizon on the far side.
    float zenith = c.at(c.width / 2, 0).x, nadir = c.at(c.width / 2, c.height - 1).x;
    EXPECT_GT(zenith, 0.88f); // measured 0.915
    EXPECT_LT(nadir, 0.12f);  // measured 0.085
    // Just below the horizon: the GGX lobe of roughness 0.5 reaches a little of the bright half,
    // the sheen lobe several times as much (measured 0.390 against 0.082).
    float sheenBelow = c.at(c.width / 2, c.height / 2 + 1).x;
    float ggxBelow = g.at(g.width / 2, g.height / 2 + 1).x;
    std::printf("[ figures ] sheen level %u: zenith %.3f, nadir %.3f, below the horizon %.3f "
                "(GGX %.3f)\n",
                level, zenith, nadir, sheenBelow, ggxBelow);
    EXPECT_GT(sheenBelow, 3.0f * ggxBelow) << "sheen " << sheenBelow << ", GGX " << ggxBelow;
}

// Each GGX level against a plain quadrature of its lobe over every source texel (weights
// D(h) n.l with v = n, as the split sum defines the prefiltered radiance): an environment with a
// small bright window over a dim gradient, where a lobe drawn too wide (too few samples, too
// coarse a source MIP, too coarse a level) loses the window's peak and spreads it around.
TEST(EnvironmentPrefilter, GgxLevelsMatchQuadratureAroundABrightWindow) {
    WorkerPool pool(2);
    EquirectImage source = makeEquirect(256, 128, glm::vec3(0.0f));
    for (uint32_t y = 0; y < source.height; ++y)
        for (uint32_t x = 0; x < source.width; ++x) {
            glm::vec3 d =
                equirectDirection({(x + 0.5f) / source.width, (y + 0.5f) / source.height});
            bool window = glm::dot(d, glm::normalize(glm::vec3(0.3f, 0.5f, 0.8f))) > 0.985f;
            source.at(x, y) =
                glm::vec3(0.3f + 0.3f * d.y) + (window ? glm::vec3(40.0f) : glm::vec3(0.0f));
        }
    PrefilterSettings s; // the default sizes, samples and level count
    s.specularWidth = 256;
    std::vector<EquirectImage> levels = prefilterSpecular(source, s, pool);
    ASSERT_EQ(levels.size(), size_t(s.specularLevels));
    struct Tap {
        glm::dvec3 d;
        double radiance, solidAngle;
    };
    std::vector<Tap> taps;
    for (uint32_t y = 0; y < source.height; ++y)
        for (uint32_t x = 0; x < source.width; ++x)
            taps.push_back({glm::dvec3(equirectDirection(
                                {(x + 0.5f) / source.width, (y + 0.5f) / source.height})),
                            double(source.at(x, y).x),
                            equirectTexelSolidAngle(source.width, source.height, y)});
    for (uint32_t l = 1; l < levels.size(); ++l) {
        const EquirectImage& level = levels[l];
        // Texel centres only where a level is 32 texels wide or more (coarser levels hold the
        // mean over each texel).
        if (level.width < 32) continue;
        double a = double(l) / double(levels.size() - 1), a2 = a * a * a * a;
        double peakExact = 0.0, peakOurs = 0.0, squared = 0.0, norm = 0.0;
        for (uint32_t y = 0; y < level.height; ++y)
            for (uint32_t x = 0; x < level.width; ++x) {
                glm::dvec3 n(
                    equirectDirection({(x + 0.5f) / level.width, (y + 0.5f) / level.height}));
                double sum = 0.0, weights = 0.0;
                for (const Tap& t : taps) {
                    double nl = glm::dot(n, t.d);
                    if (nl <= 0.0) continue;
                    double nh = glm::dot(n, glm::normalize(n + t.d));
                    double den = nh * nh * (a2 - 1.0) + 1.0;
                    double w = a2 / (kPi * den * den) * nl * t.solidAngle;
                    sum += w * t.radiance, weights += w;
                }
                double exact = sum / weights, ours = level.at(x, y).x;
                peakExact = std::max(peakExact, exact), peakOurs = std::max(peakOurs, ours);
                squared += (ours - exact) * (ours - exact), norm += exact * exact;
            }
        double rms = std::sqrt(squared / norm);
        std::printf("[ figures ] GGX level %u (roughness %.2f, %ux%u): peak %.3f of the "
                    "quadrature's %.3f (ratio %.3f), relative RMS error %.4f\n",
                    l, a, level.width, level.height, peakOurs, peakExact, peakOurs / peakExact,
                    rms);
        // Measured: peak ratios 0.999, 1.003, 0.996 and RMS errors 0.0093, 0.0173, 0.0252 at
        // levels 1-3.
        EXPECT_NEAR(peakOurs / peakExact, 1.0, 0.01) << "level " << l;
        EXPECT_LT(rms, 0.028) << "level " << l;
    }
}

// Directional albedo of the GGX specular with F = 1 (scale + bias), or of shadel's Charlie
// sheen, by a plain quadrature over the hemisphere of light directions: an oracle independent of
// the table's importance sampling.
double albedoQuadrature(double nv, double roughness, bool sheen) {
    double a = roughness * roughness, a2 = a * a;
    glm::dvec3 v(std::sqrt(1.0 - nv * nv), 0.0, nv);
    const int kT = 512, kP = 256;
    double sum = 0.0;
    for (int i = 0; i < kT; ++i)
        for (int j = 0; j < kP; ++j) {
            double cosT = (i + 0.5) / kT, phi = 2.0 * kPi * (j + 0.5) / kP;
            double sinT = std::sqrt(1.0 - cosT * cosT);
            glm::dvec3 l(sinT * std::cos(phi), sinT * std::sin(phi), cosT);
            glm::dvec3 h = glm::normalize(l + v);
            if (sheen) {
                double sin2 = std::max(1.0 - h.z * h.z, 0.0078125);
                double D = (2.0 + 1.0 / a) * std::pow(sin2, 0.5 / a) / (2.0 * kPi);
                sum += D / (4.0 * (cosT + nv - cosT * nv)) * cosT;
                continue;
            }
            double d = h.z * h.z * (a2 - 1.0) + 1.0;
            double D = a2 / (kPi * d * d);
            double gv = cosT * std::sqrt(nv * nv * (1.0 - a2) + a2);
            double gl = nv * std::sqrt(cosT * cosT * (1.0 - a2) + a2);
            sum += D * 0.5 / (gv + gl) * cosT; // d(omega) = d(cos) d(phi)
        }
    return sum * (1.0 / kT) * (2.0 * kPi / kP);
}

TEST(EnvironmentBrdf, TableMatchesKnownValuesAndQuadrature) {
    WorkerPool pool(2);
    const uint32_t n = 32;
    BrdfTable t = integrateBrdf(n, pool);
    ASSERT_EQ(t.texels.size(), size_t(n) * n);
    // n.v -> 1, roughness -> 0: a mirror reflects all, Fresnel at F0.
    glm::vec3 mirror = t.texels[n - 1];
    EXPECT_NEAR(mirror.x, 1.0f, 0.02f);
    EXPECT_NEAR(mirror.y, 0.0f, 0.01f);
    float largest = 0.0f;
    for (const glm::vec3& v : t.texels) largest = std::max(largest, v.x + v.y);
    EXPECT_LE(largest, 1.001f) << "scale + bias is a directional albedo";
    // Against quadrature where the lobes are wide enough for a 512 x 256 grid.
    double worst = 0.0, worstSheen = 0.0;
    for (uint32_t y : {12u, 20u, 31u})
        for (uint32_t x : {2u, 10u, 24u}) {
            double nv = (x + 0.5) / n, r = (y + 0.5) / n;
            glm::vec3 v = t.texels[size_t(y) * n + x];
            double q = albedoQuadrature(nv, r, false);
            worst = std::max(worst, std::abs(double(v.x + v.y) - q));
            worstSheen =
                std::max(worstSheen, std::abs(double(v.z) - albedoQuadrature(nv, r, true)));
        }
    // Measured 0.0219 (grazing, n.v 0.078) and 0.00053.
    EXPECT_LT(worst, 0.024) << "largest GGX difference to quadrature " << worst;
    EXPECT_LT(worstSheen, 0.0006) << "largest sheen difference to quadrature " << worstSheen;
    // The sheen's albedo is finite and non-negative; it exceeds 1 at grazing views of a smooth
    // sheen (the visibility term is not energy conserving), larger at grazing for a rough one.
    for (const glm::vec3& v : t.texels) {
        EXPECT_TRUE(std::isfinite(v.z));
        EXPECT_GE(v.z, 0.0f);
    }
    EXPECT_GT(t.texels[size_t(n - 1) * n + 0].z, t.texels[size_t(n - 1) * n + n - 1].z);
}

} // namespace
} // namespace shadel
