#pragma once
// Scenes made in code, deterministic (fixed seeds, no clocks): the default test content of the
// engine. Units are metres, Y up, glTF conventions.
#include <string>
#include <vector>

#include "scene/scene.h"

namespace shadel {

// Names accepted after "builtin:", the default first.
std::vector<std::string> builtinSceneNames();

// builtin:many's instance count: its default and the most `--instances` accepts.
constexpr uint32_t kManyDefaultInstances = 10000;
constexpr uint32_t kManyMaxInstances = 1000000;

struct BuiltinSceneOptions {
    uint32_t instances = 0;          // builtin:many (--instances): 0 = its default
    uint32_t galleryTextureSize = 0; // builtin:textures (--gallery-texture-size): 0 = 2048
};

// Builds the named scene; an unknown name or an option the scene does not take (or out of
// range) throws InputError.
Scene makeBuiltinScene(const std::string& name, const BuiltinSceneOptions& options = {});

} // namespace shadel
