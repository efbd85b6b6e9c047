#pragma once
// The environment of scenes authored with a sky colour and an ambient colour (night scenes,
// closed rooms: Scene::Environment::Hemisphere): a radiance that is linear in the direction's
// height, a + b * y, whose cosine-weighted irradiance over pi is a + (2/3) b n.y. Its a and b are
// chosen so that this equals the hemisphere ambient the renderer used before image-based
// lighting, mix(ambient * 0.5, ambient + sky * 0.15, n.y * 0.5 + 0.5), exactly, as long as the
// radiance below stays non-negative (ambient * 2.5 >= ambient + sky * 0.15 per channel). Past
// that (a black ambient under a sky) the radiance is clamped at 0 and a and b are refitted so
// that the irradiance facing straight up and straight down still match; between them it is close
// (tests/unit/test_environment_maps.cpp measures both cases).
#include <glm/glm.hpp>

#include "render/environment/equirect.h"

namespace shadel {

// The old hemisphere ambient for a normal of height ny (the reference the map reproduces).
glm::vec3 hemisphereAmbient(glm::vec3 skyColor, glm::vec3 ambientColor, float ny);

EquirectImage hemisphereRadiance(glm::vec3 skyColor, glm::vec3 ambientColor, uint32_t width,
                                 uint32_t height);

} // namespace shadel
