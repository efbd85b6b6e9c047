#pragma once
// Built-in scenes of the lighting work: a night street with thousands of lights of
// every kind, and a small room whose light blockers keep its light inside.
#include "scene/scene.h"

namespace shadel {

// builtin:lights: `town` (builtin:default) at night: a dim moon, >= 2000 lights of every kind
// along its streets (omni, round and square spots, tubes, darks, clip-planed lights, gobo spots,
// textured area lights as shop signs), and small rooms along the avenue with light blockers in
// their walls and portals in their doorways.
Scene makeLightsScene(Scene town);

// builtin:blockers: one closed-roofless room with a lamp inside, on open ground, in the dark.
// Blockers in its walls (a portal in the doorway) keep the lamp's light from leaking through.
Scene makeBlockersScene();

// builtin:textured-lights: a corner of two walls on a floor at night, lit by the two textured
// light kinds: gobo spots (a window pattern on the back wall, stained glass on the floor) and
// textured area lights (a shop sign over the floor, a coloured panel facing the side wall),
// plus a string of small lamps along the wall top. Textures are generated here.
Scene makeTexturedLightsScene();

// The light textures both scenes use (RGBA8, sRGB, top row first), appended to scene.textures;
// returns the index. Kinds: window (a four-pane window gobo: white panes, dark frame and cross),
// stained glass (a gobo of 3x3 coloured panes in dark lead), sign (a shop sign: coloured
// letters-like bars on red), panel (a fine orange/yellow checker: its mean is its colour at any
// scale over 4 texels).
enum class LightTexture { Window, StainedGlass, Sign, Panel };
int32_t addLightTexture(Scene& scene, LightTexture kind);

// Room geometry of both scenes: 4 walls of `height` around an interior of `size` (x, z) centred
// at `center` on the ground, a doorway of `doorWidth` x `doorHeight` in the +z wall (0: none).
// Each wall's mid-plane becomes a blocker (the doorway a portal); returns their indices.
std::vector<uint32_t> addRoom(Scene& scene, const std::string& name, glm::vec3 center,
                              glm::vec2 size, float height, float doorWidth, float doorHeight,
                              uint32_t wallMaterial);

} // namespace shadel
