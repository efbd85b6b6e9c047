#pragma once
// The built-in clear sky: single Rayleigh and Mie scattering with ozone absorption through a
// spherical atmosphere (Earth's: ground 6360 km, top 6460 km), integrated on the CPU, plus a
// multiple-scattering term (an isotropic second order over the sphere of directions, summed as
// a geometric series, stored per altitude and sun angle), and the ground below the horizon as a
// Lambertian albedo lit by the sun and the sky.
//
// Scale: the radiance is in the units of the scene's sun. The sun's irradiance at the top of
// the atmosphere is chosen so that, after the atmosphere's transmittance toward the sun, it
// equals `sunColor` at the observer: the directional light the renderer already draws and this
// sky are one consistent daylight.
#include <glm/glm.hpp>

#include "render/environment/equirect.h"

namespace shadel {

class WorkerPool;

struct SkyParameters {
    glm::vec3 sunDirection{0.3f, -1.0f, 0.2f}; // the way sunlight travels (GpuScene's)
    glm::vec3 sunColor{1.0f};                  // colour x intensity: irradiance facing the sun
    float groundAlbedo = 0.3f;
    float observerAltitudeKm = 0.1f;
};

// The sun's angular radius (0.2666 degrees) and the solid angle of its disc.
constexpr double kSunAngularRadius = 0.004654;
double sunSolidAngle();

// Sky and ground radiance, without the sun's disc (the directional light carries the sun).
// Rows run on `pool`; the result does not depend on its thread count.
EquirectImage renderSky(const SkyParameters& sky, uint32_t width, uint32_t height,
                        WorkerPool& pool);

// The sun's irradiance before the atmosphere (per channel), and the atmosphere's transmittance
// from the observer toward the sun as the sky uses it (from a table). For a sun under 2 degrees
// of elevation the top-of-atmosphere irradiance is the one of a sun at 2 degrees, so a setting
// sun dims the sky instead of blowing it up.
glm::dvec3 skyTopOfAtmosphereIrradiance(const SkyParameters& sky);
glm::dvec3 skySunTransmittance(const SkyParameters& sky);
// The same transmittance integrated directly along the ray in `steps` steps (tests' oracle).
glm::dvec3 skySunTransmittanceIntegrated(const SkyParameters& sky, int steps);

// Radiance of the sun's disc seen from the observer: sunColor over the disc's solid angle.
glm::vec3 sunDiscRadiance(glm::vec3 sunColor);

} // namespace shadel
