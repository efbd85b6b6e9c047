#pragma once
// Built-in scenes of the lighting work (seed 001): a night street with thousands of lights of
// every kind, and a small room whose light blockers keep its light inside.
#include "scene/scene.h"

namespace shadel {

// builtin:lights: `town` (builtin:default) at night: a dim moon, >= 2000 lights of every kind
// along its streets (omni, round and square spots, tubes, darks, clip-planed lights), and small
// rooms along the avenue with light blockers in their walls and portals in their doorways.
Scene makeLightsScene(Scene town);

// builtin:blockers: one closed-roofless room with a lamp inside, on open ground, in the dark.
// Blockers in its walls (a portal in the doorway) keep the lamp's light from leaking through.
Scene makeBlockersScene();

// Room geometry of both scenes: 4 walls of `height` around an interior of `size` (x, z) centred
// at `center` on the ground, a doorway of `doorWidth` x `doorHeight` in the +z wall (0: none).
// Each wall's mid-plane becomes a blocker (the doorway a portal); returns their indices.
std::vector<uint32_t> addRoom(Scene& scene, const std::string& name, glm::vec3 center,
                              glm::vec2 size, float height, float doorWidth, float doorHeight,
                              uint32_t wallMaterial);

} // namespace shadel
