#pragma once
// The environment on the GPU: the maps of environment_maps.h uploaded (specular, sheen and
// irradiance RGBA32F, background and BRDF table RGBA16F, each named for RenderDoc as
// "environment.*"), in the bindless table, and the GpuEnvironment shaders read them through
// (shaders/environment/environment.glsl). The renderer embeds `constants` in its frame
// constants; intensity and rotation can change between frames without rebuilding anything.
#include <string>

#include "common/shared_types.h"
#include "render/environment/environment_maps.h"
#include "rhi/gpu.h"

namespace shadel {

struct GpuScene;
struct RenderSettings;
struct Scene;

struct EnvironmentState {
    EnvironmentKind kind = EnvironmentKind::None;
    TextureHandle specular, irradiance, background, brdf, sheen;
    TextureReadView specularView, irradianceView, backgroundView, brdfView, sheenView;
    gpu::GpuEnvironment constants{0, 0, 0, 0, 0, ENVIRONMENT_FLAG_NONE}; // until created
    bool fromCache = false;
    double seconds = 0.0; // building or loading the maps (CPU)
};

// Uploads `maps` (kind None: the BRDF table only, and the NONE flag).
void createEnvironment(Gpu& gpu, EnvironmentState& state, const EnvironmentMaps& maps,
                       float intensity, float rotationDegrees);
// From the render settings (environment, environmentGiven, environmentIntensity,
// environmentRotationDegrees), the scene (its hemisphere colours and Scene::environment) and
// the GPU scene's sun (direction and colour x intensity): loads or builds the maps in cacheDir
// ("" = no cache), then uploads them. Throws InputError for a bad environment file.
void createEnvironment(Gpu& gpu, EnvironmentState& state, const RenderSettings& settings,
                       const GpuScene& scene, const std::string& cacheDir);
// Intensity and rotation for the next frames (the maps stay).
void setEnvironmentView(EnvironmentState& state, float intensity, float rotationDegrees);
void destroyEnvironment(Gpu& gpu, EnvironmentState& state);

} // namespace shadel
