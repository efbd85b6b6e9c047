#pragma once
// Scenes made in code, deterministic (fixed seeds, no clocks): the default test content of the
// engine. Units are metres, Y up, glTF conventions.
#include <string>
#include <vector>

#include "scene/scene.h"

namespace shadel {

// Names accepted after "builtin:", the default first.
std::vector<std::string> builtinSceneNames();

// Builds the named scene; an unknown name throws InputError.
Scene makeBuiltinScene(const std::string& name);

} // namespace shadel
