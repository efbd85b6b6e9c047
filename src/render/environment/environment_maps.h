#pragma once
// The environment's maps, from the settings and the scene to the CPU images the GPU side
// (environment_state.h) uploads: built once per source and cached on disk by content.
//
// Sizes (defaults of PrefilterSettings): specular 512x256 at level 0 and 5 levels down to 32x16
// (level l: GGX of perceptual roughness l / 4); sheen 128x64 and 7 levels down to 2x1 (the Charlie
// lobe of sheen roughness l / 6); irradiance / pi 64x32; BRDF table 64x64;
// background the source up to 2048x1024 (the sky: 1024x512; the hemisphere: its sky colour).
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "render/environment/equirect.h"
#include "render/environment/prefilter.h"
#include "scene/scene.h"

namespace shadel {

enum class EnvironmentKind { None, File, Sky, Hemisphere };

struct EnvironmentRequest {
    EnvironmentKind kind = EnvironmentKind::None;
    std::string path;                             // File: a .hdr or .exr
    glm::vec3 sunDirection{0.0f, -1.0f, 0.0f};    // Sky: the way sunlight travels
    glm::vec3 sunColor{0.0f};                     // Sky: colour x intensity (GpuScene::sunColor)
    glm::vec3 skyColor{0.0f}, ambientColor{0.0f}; // Hemisphere
};

// What lights the scene: `setting` (RenderSettings::environment: "builtin:sky", "none" or a
// file) when it was given on the command line or the scene asks for a sky; the scene's
// hemisphere (sky and ambient colours) when it asks for one and no setting was given. Throws
// InputError for an unknown "builtin:" name.
EnvironmentRequest environmentRequest(const std::string& setting, bool settingGiven,
                                      const Scene& scene, glm::vec3 sunDirection,
                                      glm::vec3 sunColor);
// The same from the scene's environment kind and colours (as the GPU scene keeps them).
EnvironmentRequest environmentRequest(const std::string& setting, bool settingGiven,
                                      Scene::Environment sceneEnvironment, glm::vec3 skyColor,
                                      glm::vec3 ambientColor, glm::vec3 sunDirection,
                                      glm::vec3 sunColor);

struct EnvironmentMaps {
    EnvironmentKind kind = EnvironmentKind::None;
    std::vector<EquirectImage> specular; // level l: perceptual roughness l / (levels - 1)
    std::vector<EquirectImage> sheen; // level l: Charlie lobe of sheen roughness l / (levels - 1)
    EquirectImage irradiance;         // irradiance / pi
    EquirectImage background;         // what the camera sees (no sun disc)
    BrdfTable brdf;
    // The sun's disc, drawn only in the background (the directional light carries the sun).
    glm::vec3 sunDirection{0.0f, -1.0f, 0.0f};
    glm::vec3 sunDiscRadiance{0.0f}; // 0: no disc
    bool fromCache = false;
    double seconds = 0.0; // wall time to build or load
};

// Loads the maps from `cacheDir` ("" = no cache) or builds them (printing progress) and writes
// them there. `threads` 0 = the machine's. Throws InputError for a bad file (see
// environment_file.h). Kind None gives empty maps and the BRDF table only.
EnvironmentMaps loadEnvironmentMaps(const EnvironmentRequest& request, const std::string& cacheDir,
                                    const PrefilterSettings& settings = {}, uint32_t threads = 0);

// The source radiance before prefiltering (the sky rendered, the file decoded, the hemisphere),
// exposed for tests.
EquirectImage environmentSource(const EnvironmentRequest& request, uint32_t threads = 0);

} // namespace shadel
