#pragma once
// The built-in scene of the material programs (render/materials, docs/materials.md).
#include "scene/scene.h"

namespace shadel {

// builtin:materials: a terrain (the three-stage program builtin:terrain: a material from the
// height, the normal computed once from the height function, then the lighting) under a sun
// and a warm lamp, with spheres and a box shaded by the glTF PBR programs: the built-in one
// (plain and brick materials) and the smallest written one (builtin:gltf_pbr_factors), and a
// checker wall whose program (builtin:checker_accumulate) folds one jittered sample a frame into
// a preserved layer. Cameras: main (the whole), terrain (close over it), factors (the program
// spheres and box only), checker (the wall only).
Scene makeMaterialsScene();

} // namespace shadel
