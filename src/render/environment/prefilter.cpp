#include "render/environment/prefilter.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "core/worker_pool.h"

namespace shadel {

namespace {

constexpr double kPi = 3.14159265358979323846;

glm::dvec2 hammersley(uint32_t i, uint32_t n) {
    uint32_t bits = i;
    bits = (bits << 16u) | (bits >> 16u);
    bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
    bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
    bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
    bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
    return {(double(i) + 0.5) / n, double(bits) * 2.3283064365386963e-10};
}

// A GGX half vector around +Z for alpha = roughness^2.
glm::dvec3 sampleGgx(glm::dvec2 xi, double alpha) {
    double a2 = alpha * alpha;
    double cosT = std::sqrt((1.0 - xi.x) / (1.0 + (a2 - 1.0) * xi.x));
    double sinT = std::sqrt(std::max(0.0, 1.0 - cosT * cosT));
    double phi = 2.0 * kPi * xi.y;
    return {sinT * std::cos(phi), sinT * std::sin(phi), cosT};
}

double ggx(double nh, double a2) {
    double d = nh * nh * (a2 - 1.0) + 1.0;
    return a2 / (kPi * d * d);
}

// One sample of the specular lobe in the frame of the normal (+Z): direction, n.l, source LOD.
struct LobeSample {
    glm::vec3 l;
    float weight;
    float lod;
};

// The Charlie (sheen) distribution for alpha = roughness^2, unclamped.
double charlie(double nh, double alpha) {
    double inv = 1.0 / alpha;
    return (2.0 + inv) * std::pow(std::max(1.0 - nh * nh, 0.0), inv * 0.5) / (2.0 * kPi);
}

// A Charlie half vector around +Z (sin theta = xi^(alpha / (2 alpha + 1))).
glm::dvec3 sampleCharlie(glm::dvec2 xi, double alpha) {
    double sinT = std::pow(xi.x, alpha / (2.0 * alpha + 1.0));
    double cosT = std::sqrt(std::max(0.0, 1.0 - sinT * sinT));
    double phi = 2.0 * kPi * xi.y;
    return {sinT * std::cos(phi), sinT * std::sin(phi), cosT};
}

std::vector<LobeSample> lobeSamples(PrefilterLobe lobe, double roughness, uint32_t count,
                                    double texelSolidAngle) {
    std::vector<LobeSample> out;
    double alpha = std::max(roughness * roughness, 1e-4);
    // With n = v, directions above the horizon come from half vectors within 45 degrees of n.
    // Most of a thin Charlie lobe's half vectors lie near the tangent plane, beyond that: its
    // samples are drawn from the part within (the share `within` of the lobe), so every one
    // counts and the level is the lobe's mean over the directions above the horizon.
    double within = 1.0;
    if (lobe == PrefilterLobe::Charlie)
        within = std::pow(std::sqrt(0.5), (2.0 * alpha + 1.0) / alpha); // CDF of sin(theta)
    for (uint32_t i = 0; i < count; ++i) {
        glm::dvec2 xi = hammersley(i, count);
        glm::dvec3 h = lobe == PrefilterLobe::Ggx ? sampleGgx(xi, alpha)
                                                  : sampleCharlie({xi.x * within, xi.y}, alpha);
        glm::dvec3 l = 2.0 * h.z * h - glm::dvec3(0.0, 0.0, 1.0);
        if (l.z <= 0.0) continue;
        // With n = v the pdf of l is D n.h / (4 v.h) = D / 4 (over `within` of the lobe); the
        // sample stands for 1 / (count * pdf) steradians. It reads the source MIP whose texels
        // are about that size (half a level finer: a full level coarser blurs a small bright
        // source past the lobe, and none at all lets single texels alias between samples).
        double d = lobe == PrefilterLobe::Ggx ? ggx(h.z, alpha * alpha) : charlie(h.z, alpha);
        double pdf = std::max(d / 4.0 / std::max(within, 1e-300), 1e-12);
        double sampleSolidAngle = 1.0 / (double(count) * pdf);
        double lod = std::max(0.0, 0.5 * std::log2(sampleSolidAngle / texelSolidAngle) + 0.5);
        out.push_back({glm::vec3(l), float(l.z), float(lod)});
    }
    return out;
}

glm::vec3 samplePyramid(const std::vector<EquirectImage>& pyramid, glm::vec3 d, float lod) {
    glm::vec2 uv = equirectUv(d);
    // Not past the level 16 texels wide: coarser ones, bilinear near the poles, smear energy
    // across latitudes more than the lobe does.
    float top = float(pyramid.size() - 1);
    for (size_t l = 0; l < pyramid.size(); ++l)
        if (pyramid[l].width <= 16) {
            top = float(l);
            break;
        }
    lod = std::min(lod, top);
    uint32_t l0 = uint32_t(lod);
    uint32_t l1 = std::min(l0 + 1, uint32_t(top));
    float t = lod - float(l0);
    glm::vec3 a = sampleEquirect(pyramid[l0], uv);
    return t > 0.0f ? glm::mix(a, sampleEquirect(pyramid[l1], uv), t) : a;
}

glm::mat3 frameAround(glm::vec3 n) {
    glm::vec3 up = std::abs(n.y) < 0.999f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    glm::vec3 t = glm::normalize(glm::cross(up, n));
    return glm::mat3(t, glm::cross(n, t), n);
}

glm::vec3 texelDirection(uint32_t x, uint32_t y, uint32_t width, uint32_t height) {
    return equirectDirection(
        glm::vec2((float(x) + 0.5f) / float(width), (float(y) + 0.5f) / float(height)));
}

} // namespace

std::vector<EquirectImage> prefilterSpecular(const EquirectImage& source,
                                             const PrefilterSettings& settings, WorkerPool& pool,
                                             const PrefilterProgress& progress) {
    return prefilterLobes(source, PrefilterLobe::Ggx, settings.specularWidth,
                          settings.specularLevels, settings.specularSamples, pool, progress);
}

std::vector<EquirectImage> prefilterSheen(const EquirectImage& source,
                                          const PrefilterSettings& settings, WorkerPool& pool,
                                          const PrefilterProgress& progress) {
    return prefilterLobes(source, PrefilterLobe::Charlie, settings.sheenWidth,
                          sheenLevelCount(settings), settings.specularSamples, pool, progress);
}

uint32_t sheenLevelCount(const PrefilterSettings& settings) {
    uint32_t fit = 1;
    while ((settings.sheenWidth >> fit) >= 2) ++fit; // level fit - 1 is 2 texels wide
    return std::max(std::min(settings.sheenLevels, fit), 2u);
}

std::vector<EquirectImage> prefilterLobes(const EquirectImage& source, PrefilterLobe lobeKind,
                                          uint32_t width, uint32_t levelsWanted,
                                          uint32_t samplesWanted, WorkerPool& pool,
                                          const PrefilterProgress& progress) {
    uint32_t w0 = width, h0 = w0 / 2;
    bool ggxLobe = lobeKind == PrefilterLobe::Ggx;
    std::vector<EquirectImage> pyramid{resampleEquirect(source, w0, h0)};
    while (pyramid.back().height > 1 && pyramid.back().width % 2 == 0)
        pyramid.push_back(downsampleEquirect(pyramid.back()));
    // GGX level 0 is the lobe of roughness 0, the source itself. The Charlie lobe of roughness 0
    // is a ring at the horizon, with no weight (n.l = 0) above it: its level 0 holds the
    // smoothest sheen materials have (kMinSheenRoughness, the shaders' clamp).
    std::vector<EquirectImage> levels;
    if (ggxLobe) levels.push_back(pyramid[0]);
    uint32_t levelCount = std::max(levelsWanted, 2u);
    uint32_t first = ggxLobe ? 1 : 0;
    // Work in texel-samples, for the progress.
    double total = 0.0, done = 0.0;
    for (uint32_t l = first; l < levelCount; ++l)
        total += double(std::max(w0 >> l, 2u)) * std::max(h0 >> l, 1u);
    const double texelSolidAngle = 4.0 * kPi / (double(w0) * h0);
    for (uint32_t l = first; l < levelCount; ++l) {
        uint32_t w = std::max(w0 >> l, 2u), h = std::max(h0 >> l, 1u);
        double roughness = double(l) / double(levelCount - 1);
        if (!ggxLobe) roughness = std::max(roughness, double(kMinSheenRoughness));
        std::vector<LobeSample> lobe =
            lobeSamples(lobeKind, roughness, samplesWanted, texelSolidAngle);
        EquirectImage level = makeEquirect(w, h);
        std::atomic<uint32_t> rows{0};
        // Levels under 32 texels wide hold the mean of the filtered radiance over each texel
        // (k x k directions), not its value at the centre: their texels are as wide as the lobe,
        // and the centre alone would lose or gain energy.
        uint32_t k = std::clamp(32u / w, 1u, 8u);
        pool.parallelFor(h, [&](uint32_t y, uint32_t worker) {
            for (uint32_t x = 0; x < w; ++x) {
                glm::vec3 texel(0.0f);
                float area = 0.0f;
                for (uint32_t j = 0; j < k; ++j)
                    for (uint32_t i = 0; i < k; ++i) {
                        glm::vec2 uv((float(x) + (float(i) + 0.5f) / float(k)) / float(w),
                                     (float(y) + (float(j) + 0.5f) / float(k)) / float(h));
                        glm::vec3 n = equirectDirection(uv);
                        glm::mat3 frame = frameAround(n);
                        glm::vec3 sum(0.0f);
                        float weights = 0.0f;
                        for (const LobeSample& s : lobe) {
                            sum += samplePyramid(pyramid, frame * s.l, s.lod) * s.weight;
                            weights += s.weight;
                        }
                        float solidAngle = std::sqrt(std::max(0.0f, 1.0f - n.y * n.y));
                        if (weights > 0.0f) texel += sum / weights * solidAngle;
                        area += solidAngle;
                    }
                level.at(x, y) = area > 0.0f ? texel / area : glm::vec3(0.0f);
            }
            uint32_t finished = ++rows;
            if (worker == 0 && progress) progress(float((done + double(finished) * w) / total));
        });
        done += double(w) * h;
        levels.push_back(std::move(level));
    }
    if (progress) progress(1.0f);
    return levels;
}

EquirectImage prefilterIrradiance(const EquirectImage& source, uint32_t width, WorkerPool& pool) {
    // Every texel of a 128 x 64 level (5.6 x 2.8 degree texels at most; a cosine lobe is smooth).
    EquirectImage level = resampleEquirect(source, 128, 64);
    struct Tap {
        glm::vec3 direction;
        glm::vec3 energy; // radiance x solid angle
        float solidAngle;
    };
    std::vector<Tap> taps;
    taps.reserve(level.texels.size());
    for (uint32_t y = 0; y < level.height; ++y) {
        float omega = float(equirectTexelSolidAngle(level.width, level.height, y));
        for (uint32_t x = 0; x < level.width; ++x)
            taps.push_back(
                {texelDirection(x, y, level.width, level.height), level.at(x, y) * omega, omega});
    }
    uint32_t height = width / 2;
    EquirectImage out = makeEquirect(width, height);
    pool.parallelFor(height, [&](uint32_t y, uint32_t) {
        for (uint32_t x = 0; x < width; ++x) {
            glm::vec3 n = texelDirection(x, y, width, height);
            glm::dvec3 sum(0.0);
            double weights = 0.0;
            for (const Tap& t : taps) {
                float c = glm::dot(n, t.direction);
                if (c <= 0.0f) continue;
                sum += glm::dvec3(t.energy) * double(c);
                weights += double(c) * t.solidAngle;
            }
            // The cosine's integral is pi; dividing by its discrete sum keeps a uniform
            // environment exact.
            out.at(x, y) = weights > 0.0 ? glm::vec3(sum / weights) : glm::vec3(0.0f);
        }
    });
    return out;
}

namespace {

glm::dvec2 specularScaleBias(double nv, double roughness, uint32_t samples) {
    glm::dvec3 v(std::sqrt(std::max(0.0, 1.0 - nv * nv)), 0.0, nv);
    double alpha = std::max(roughness * roughness, 1e-4), a2 = alpha * alpha;
    glm::dvec2 sum(0.0);
    for (uint32_t i = 0; i < samples; ++i) {
        glm::dvec3 h = sampleGgx(hammersley(i, samples), alpha);
        double vh = glm::dot(v, h);
        glm::dvec3 l = 2.0 * vh * h - v;
        double nl = l.z, nh = h.z;
        if (nl <= 0.0 || vh <= 0.0) continue;
        // Height-correlated Smith visibility V = G / (4 n.l n.v), as the glTF BRDF.
        double gv = nl * std::sqrt(nv * nv * (1.0 - a2) + a2);
        double gl = nv * std::sqrt(nl * nl * (1.0 - a2) + a2);
        double vis = 0.5 / (gv + gl);
        // f n.l / pdf with pdf = D n.h / (4 v.h): the D cancels.
        double weight = 4.0 * vis * nl * vh / nh;
        double fc = std::pow(1.0 - vh, 5.0);
        sum += glm::dvec2((1.0 - fc) * weight, fc * weight);
    }
    return sum / double(samples);
}

// The sheen's directional albedo: the integral of D_charlie V n.l, with shadel's sheen terms
// (shaders/common/lighting.glsl: the distribution with sin^2 clamped at 1/128, the visibility
// 1 / (4 (n.l + n.v - n.l n.v))), importance sampled by the unclamped Charlie distribution.
double sheenAlbedo(double nv, double roughness, uint32_t samples) {
    glm::dvec3 v(std::sqrt(std::max(0.0, 1.0 - nv * nv)), 0.0, nv);
    double alpha = std::max(roughness * roughness, 1e-4), inv = 1.0 / alpha;
    double sum = 0.0;
    for (uint32_t i = 0; i < samples; ++i) {
        glm::dvec2 xi = hammersley(i, samples);
        double sinT = std::pow(xi.x, alpha / (2.0 * alpha + 1.0));
        double cosT = std::sqrt(std::max(0.0, 1.0 - sinT * sinT));
        double phi = 2.0 * kPi * xi.y;
        glm::dvec3 h(sinT * std::cos(phi), sinT * std::sin(phi), cosT);
        double vh = glm::dot(v, h);
        if (vh <= 0.0) continue;
        glm::dvec3 l = 2.0 * vh * h - v;
        double nl = l.z, nh = h.z;
        if (nl <= 0.0 || nh <= 1e-6) continue;
        double sin2 = std::max(1.0 - nh * nh, 0.0);
        double unclamped = (2.0 + inv) * std::pow(sin2, inv * 0.5) / (2.0 * kPi);
        double clamped = (2.0 + inv) * std::pow(std::max(sin2, 0.0078125), inv * 0.5) / (2.0 * kPi);
        if (unclamped <= 0.0) continue;
        double vis = 1.0 / (4.0 * (nl + nv - nl * nv));
        // f n.l / pdf_l, pdf_l = D_unclamped n.h / (4 v.h).
        sum += clamped / unclamped * vis * nl * 4.0 * vh / nh;
    }
    return sum / double(samples);
}

} // namespace

BrdfTable integrateBrdf(uint32_t size, WorkerPool& pool) {
    BrdfTable table;
    table.size = size;
    table.texels.resize(size_t(size) * size);
    pool.parallelFor(size, [&](uint32_t y, uint32_t) {
        double roughness = (double(y) + 0.5) / size;
        for (uint32_t x = 0; x < size; ++x) {
            double nv = (double(x) + 0.5) / size;
            glm::dvec2 sb = specularScaleBias(nv, roughness, 1024);
            double sheen = sheenAlbedo(nv, roughness, 2048);
            table.texels[size_t(y) * size + x] = glm::vec3(float(sb.x), float(sb.y), float(sheen));
        }
    });
    return table;
}

} // namespace shadel
