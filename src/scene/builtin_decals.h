#pragma once
// builtin:decals (render/decals): a yard with a wall, a crate and a standing figure, and
// overlapping projected decals of every kind: graffiti (base colour) on the wall, a riveted
// plate (normal + base colour) across the wall and the crate, road stripes (base colour) and a
// puddle (roughness) on the ground, and AO-only contact shadows under the figure and the crate
// (character shadow: a decal that darkens only the ambient light).
#include "scene/scene.h"

namespace shadel {

Scene makeDecalsScene();

// Where the figure's contact shadow (the AO-only decal) lies: the centre of its footprint on
// the ground (the tests inspect the pixel it projects to).
glm::vec3 decalsSceneContactShadowCentre();

} // namespace shadel
