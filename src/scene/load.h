#pragma once
// The one entry point from a user's scene argument to a Scene.
#include <string>
#include <vector>

#include "scene/builtin_scenes.h"
#include "scene/gltf_import.h"
#include "scene/scene.h"

namespace shadel {

// `builtin:NAME` (see builtinSceneNames()) or a path to a .gltf / .glb file. Bad input throws
// InputError with one line naming the input and the reason.
// `builtin` carries options of built-in scenes (--instances); a file scene rejects them.
Scene loadScene(const std::string& spec, const SceneFileOptions& options = {},
                const BuiltinSceneOptions& builtin = {});

} // namespace shadel
