#include "render/environment/sky.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/worker_pool.h"

namespace shadel {

namespace {

constexpr double kPi = 3.14159265358979323846;
// Lengths in kilometres, coefficients per kilometre.
constexpr double kGround = 6360.0, kTop = 6460.0;
const glm::dvec3 kRayleighScattering(5.802e-3, 13.558e-3, 33.1e-3);
constexpr double kRayleighHeight = 8.0;
constexpr double kMieScattering = 3.996e-3, kMieExtinction = 4.440e-3;
constexpr double kMieHeight = 1.2, kMieG = 0.8;
const glm::dvec3 kOzoneAbsorption(0.650e-3, 1.881e-3, 0.085e-3);
constexpr double kOzoneCentre = 25.0, kOzoneHalfWidth = 15.0;
constexpr double kMinSunElevation = 2.0 * kPi / 180.0; // for the top-of-atmosphere scale

struct Medium {
    glm::dvec3 rayleigh; // scattering
    double mie;          // scattering
    glm::dvec3 extinction;
};

Medium mediumAt(double altitude) {
    double h = std::max(altitude, 0.0);
    Medium m;
    m.rayleigh = kRayleighScattering * std::exp(-h / kRayleighHeight);
    double mieDensity = std::exp(-h / kMieHeight);
    m.mie = kMieScattering * mieDensity;
    double ozone = std::max(0.0, 1.0 - std::abs(h - kOzoneCentre) / kOzoneHalfWidth);
    m.extinction = m.rayleigh + glm::dvec3(kMieExtinction * mieDensity) + kOzoneAbsorption * ozone;
    return m;
}

double rayleighPhase(double nu) {
    return 3.0 / (16.0 * kPi) * (1.0 + nu * nu);
}

double miePhase(double nu) { // Cornette-Shanks
    double g2 = kMieG * kMieG;
    double k = 3.0 / (8.0 * kPi) * (1.0 - g2) / (2.0 + g2);
    return k * (1.0 + nu * nu) / std::pow(1.0 + g2 - 2.0 * kMieG * nu, 1.5);
}

// Distance from radius r along a ray of cosine mu (to the zenith) to the sphere of `radius`
// (outward), and whether the ray meets the ground first.
double distanceToTop(double r, double mu) {
    double disc = r * r * (mu * mu - 1.0) + kTop * kTop;
    return std::max(0.0, -r * mu + std::sqrt(std::max(disc, 0.0)));
}
bool hitsGround(double r, double mu) {
    return mu < 0.0 && r * r * (mu * mu - 1.0) + kGround * kGround >= 0.0;
}

glm::dvec3 opticalDepth(double r, double mu, double length, int steps) {
    glm::dvec3 depth(0.0);
    double dt = length / steps;
    for (int i = 0; i <= steps; ++i) {
        double t = i * dt;
        double ri = std::sqrt(r * r + t * t + 2.0 * r * mu * t);
        double w = (i == 0 || i == steps) ? 0.5 : 1.0;
        depth += w * dt * mediumAt(ri - kGround).extinction;
    }
    return depth;
}

// Transmittance to the top of the atmosphere per (radius, zenith cosine), on a parametrization
// that resolves the horizon: x_r is the distance to the horizon over its largest value, x_mu the
// distance to the top between its least and largest values from that radius.
struct TransmittanceTable {
    static constexpr int kMu = 256, kR = 64;
    std::vector<glm::dvec3> t = std::vector<glm::dvec3>(size_t(kMu) * kR);

    TransmittanceTable() {
        double H = std::sqrt(kTop * kTop - kGround * kGround);
        for (int ir = 0; ir < kR; ++ir)
            for (int im = 0; im < kMu; ++im) {
                double rho = H * ir / (kR - 1);
                double r = std::sqrt(rho * rho + kGround * kGround);
                double dMin = kTop - r, dMax = rho + H;
                double d = dMin + (dMax - dMin) * im / (kMu - 1);
                double mu = d == 0.0 ? 1.0 : (H * H - rho * rho - d * d) / (2.0 * r * d);
                mu = std::clamp(mu, -1.0, 1.0);
                t[size_t(ir) * kMu + im] = glm::exp(-opticalDepth(r, mu, d, 256));
            }
    }
    glm::dvec3 lookup(double r, double mu) const {
        if (hitsGround(r, mu)) return glm::dvec3(0.0);
        double H = std::sqrt(kTop * kTop - kGround * kGround);
        double rho = std::sqrt(std::max(r * r - kGround * kGround, 0.0));
        double dMin = kTop - r, dMax = rho + H;
        double xMu = dMax > dMin ? (distanceToTop(r, mu) - dMin) / (dMax - dMin) : 0.0;
        double fm = std::clamp(xMu, 0.0, 1.0) * (kMu - 1),
               fr = std::clamp(rho / H, 0.0, 1.0) * (kR - 1);
        int m0 = std::min(int(fm), kMu - 2), r0 = std::min(int(fr), kR - 2);
        double tm = fm - m0, tr = fr - r0;
        auto at = [&](int ir, int im) { return t[size_t(ir) * kMu + im]; };
        return glm::mix(glm::mix(at(r0, m0), at(r0, m0 + 1), tm),
                        glm::mix(at(r0 + 1, m0), at(r0 + 1, m0 + 1), tm), tr);
    }
};

const TransmittanceTable& transmittanceTable() {
    static const TransmittanceTable table;
    return table;
}

// Multiple scattering per (altitude, sun zenith cosine), for a unit top-of-atmosphere sun: the
// second order of isotropic scattering gathered over the sphere of directions (ground bounce
// included), times 1 / (1 - f), f the fraction a unit isotropic radiance scatters back to the
// point: the series of all higher orders.
struct MultipleScatteringTable {
    static constexpr int kMu = 32, kH = 32;
    std::vector<glm::dvec3> psi = std::vector<glm::dvec3>(size_t(kMu) * kH);

    glm::dvec3 compute(double r, double muS, double albedo) const;
    glm::dvec3 lookup(double altitude, double muS) const {
        double fh = std::clamp(altitude / (kTop - kGround), 0.0, 1.0) * (kH - 1);
        double fm = std::clamp(muS * 0.5 + 0.5, 0.0, 1.0) * (kMu - 1);
        int h0 = std::min(int(fh), kH - 2), m0 = std::min(int(fm), kMu - 2);
        double th = fh - h0, tm = fm - m0;
        auto at = [&](int ih, int im) { return psi[size_t(ih) * kMu + im]; };
        return glm::mix(glm::mix(at(h0, m0), at(h0, m0 + 1), tm),
                        glm::mix(at(h0 + 1, m0), at(h0 + 1, m0 + 1), tm), th);
    }
};

glm::dvec3 MultipleScatteringTable::compute(double r, double muS, double albedo) const {
    const TransmittanceTable& lut = transmittanceTable();
    const int kDirs = 8, kSteps = 20;
    glm::dvec3 x(0.0, r, 0.0);
    glm::dvec3 s(std::sqrt(std::max(0.0, 1.0 - muS * muS)), muS, 0.0);
    glm::dvec3 second(0.0), transfer(0.0);
    for (int i = 0; i < kDirs; ++i)
        for (int j = 0; j < kDirs; ++j) {
            double cosT = 1.0 - 2.0 * (i + 0.5) / kDirs, phi = 2.0 * kPi * (j + 0.5) / kDirs;
            double sinT = std::sqrt(1.0 - cosT * cosT);
            glm::dvec3 d(sinT * std::cos(phi), cosT, sinT * std::sin(phi));
            bool ground = hitsGround(r, cosT);
            double length =
                ground ? -r * cosT - std::sqrt(r * r * (cosT * cosT - 1.0) + kGround * kGround)
                       : distanceToTop(r, cosT);
            glm::dvec3 throughput(1.0), lum(0.0), fms(0.0);
            double dt = length / kSteps;
            for (int k = 0; k < kSteps; ++k) {
                glm::dvec3 p = x + d * ((k + 0.5) * dt);
                double rp = glm::length(p);
                Medium m = mediumAt(rp - kGround);
                glm::dvec3 scattering = m.rayleigh + glm::dvec3(m.mie);
                glm::dvec3 step = glm::exp(-m.extinction * dt);
                glm::dvec3 integral = (glm::dvec3(1.0) - step) / glm::max(m.extinction, 1e-12);
                glm::dvec3 sun = lut.lookup(rp, glm::dot(p, s) / rp);
                lum += throughput * scattering * sun / (4.0 * kPi) * integral;
                fms += throughput * scattering * integral;
                throughput *= step;
            }
            if (ground) {
                glm::dvec3 p = x + d * length;
                double muG = glm::dot(p, s) / glm::length(p);
                lum += throughput * lut.lookup(kGround, muG) * std::max(muG, 0.0) * albedo / kPi;
            }
            second += lum;
            transfer += fms;
        }
    double n = double(kDirs * kDirs);
    second /= n, transfer /= n;
    return second / (glm::dvec3(1.0) - glm::min(transfer, 0.999));
}

MultipleScatteringTable multipleScattering(double albedo, WorkerPool& pool) {
    MultipleScatteringTable table;
    using T = MultipleScatteringTable;
    pool.parallelFor(uint32_t(T::kH), [&](uint32_t ih, uint32_t) {
        double r = kGround + (kTop - kGround) * ih / (T::kH - 1);
        r = std::clamp(r, kGround + 1e-3, kTop - 1e-3);
        for (int im = 0; im < T::kMu; ++im)
            table.psi[size_t(ih) * T::kMu + im] =
                table.compute(r, -1.0 + 2.0 * im / (T::kMu - 1), albedo);
    });
    return table;
}

struct SkySample {
    glm::dvec3 inscatter{0.0};
    glm::dvec3 toGround{0.0}; // transmittance to the ground (0: the ray sees the sky)
    double groundSun = 0.0;   // cosine of the sun at the ground point
    glm::dvec3 groundSunTransmittance{0.0};
};

SkySample marchView(glm::dvec3 x, glm::dvec3 d, glm::dvec3 s, const MultipleScatteringTable& ms) {
    const TransmittanceTable& lut = transmittanceTable();
    const int kSteps = 32;
    double r = glm::length(x), mu = glm::dot(x, d) / r;
    bool ground = hitsGround(r, mu);
    double length = ground ? -r * mu - std::sqrt(r * r * (mu * mu - 1.0) + kGround * kGround)
                           : distanceToTop(r, mu);
    double nu = glm::dot(d, s);
    double pr = rayleighPhase(nu), pm = miePhase(nu);
    SkySample out;
    glm::dvec3 throughput(1.0);
    double previous = 0.0;
    for (int k = 1; k <= kSteps; ++k) {
        // Quadratic spacing: short steps near the observer, where the air is densest.
        double t = length * double(k) * k / (double(kSteps) * kSteps);
        double dt = t - previous, mid = 0.5 * (t + previous);
        previous = t;
        glm::dvec3 p = x + d * mid;
        double rp = glm::length(p);
        Medium m = mediumAt(rp - kGround);
        double muS = glm::dot(p, s) / rp;
        glm::dvec3 sun = lut.lookup(rp, muS);
        glm::dvec3 source = (m.rayleigh * pr + glm::dvec3(m.mie * pm)) * sun +
                            (m.rayleigh + glm::dvec3(m.mie)) * ms.lookup(rp - kGround, muS);
        glm::dvec3 step = glm::exp(-m.extinction * dt);
        out.inscatter +=
            throughput * source * (glm::dvec3(1.0) - step) / glm::max(m.extinction, 1e-12);
        throughput *= step;
    }
    if (ground) {
        glm::dvec3 p = x + d * length;
        out.toGround = throughput;
        out.groundSun = std::max(glm::dot(p, s) / glm::length(p), 0.0);
        out.groundSunTransmittance = lut.lookup(kGround, glm::dot(p, s) / glm::length(p));
    }
    return out;
}

glm::dvec3 towardSun(const SkyParameters& sky) {
    glm::dvec3 s = -glm::dvec3(sky.sunDirection);
    double len = glm::length(s);
    return len > 0.0 ? s / len : glm::dvec3(0.0, 1.0, 0.0);
}

double observerRadius(const SkyParameters& sky) {
    return kGround + std::clamp(double(sky.observerAltitudeKm), 0.001, 50.0);
}

} // namespace

double sunSolidAngle() {
    return 2.0 * kPi * (1.0 - std::cos(kSunAngularRadius));
}

glm::vec3 sunDiscRadiance(glm::vec3 sunColor) {
    return sunColor / float(sunSolidAngle());
}

glm::dvec3 skySunTransmittance(const SkyParameters& sky) {
    return transmittanceTable().lookup(observerRadius(sky), towardSun(sky).y);
}

glm::dvec3 skySunTransmittanceIntegrated(const SkyParameters& sky, int steps) {
    double r = observerRadius(sky), mu = towardSun(sky).y;
    if (hitsGround(r, mu)) return glm::dvec3(0.0);
    return glm::exp(-opticalDepth(r, mu, distanceToTop(r, mu), steps));
}

glm::dvec3 skyTopOfAtmosphereIrradiance(const SkyParameters& sky) {
    double mu = std::max(towardSun(sky).y, std::sin(kMinSunElevation));
    glm::dvec3 t = transmittanceTable().lookup(observerRadius(sky), mu);
    return glm::dvec3(sky.sunColor) / glm::max(t, 1e-9);
}

EquirectImage renderSky(const SkyParameters& sky, uint32_t width, uint32_t height,
                        WorkerPool& pool) {
    MultipleScatteringTable ms = multipleScattering(sky.groundAlbedo, pool);
    glm::dvec3 s = towardSun(sky);
    glm::dvec3 x(0.0, observerRadius(sky), 0.0);
    std::vector<SkySample> samples(size_t(width) * height);
    pool.parallelFor(height, [&](uint32_t y, uint32_t) {
        for (uint32_t i = 0; i < width; ++i) {
            glm::vec2 uv((float(i) + 0.5f) / float(width), (float(y) + 0.5f) / float(height));
            samples[size_t(y) * width + i] = marchView(x, glm::dvec3(equirectDirection(uv)), s, ms);
        }
    });
    // The sky's irradiance on the horizontal ground, from the rows that see the sky above.
    glm::dvec3 skyIrradiance(0.0);
    for (uint32_t y = 0; y < height / 2; ++y) {
        double cosTheta = std::cos(kPi * (y + 0.5) / height);
        double omega = equirectTexelSolidAngle(width, height, y);
        for (uint32_t i = 0; i < width; ++i)
            skyIrradiance += samples[size_t(y) * width + i].inscatter * cosTheta * omega;
    }
    glm::dvec3 toa = skyTopOfAtmosphereIrradiance(sky);
    EquirectImage image = makeEquirect(width, height);
    double albedo = std::clamp(double(sky.groundAlbedo), 0.0, 1.0);
    for (size_t k = 0; k < samples.size(); ++k) {
        const SkySample& a = samples[k];
        glm::dvec3 radiance = a.inscatter;
        if (a.groundSun > 0.0 || a.toGround != glm::dvec3(0.0))
            radiance += a.toGround * albedo / kPi *
                        (a.groundSunTransmittance * a.groundSun + skyIrradiance);
        image.texels[k] = glm::vec3(radiance * toa);
    }
    return image;
}

} // namespace shadel
