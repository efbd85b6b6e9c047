#include "scene/load.h"

#include <algorithm>
#include <filesystem>

#include "core/error.h"
#include "scene/gltf_import.h"

namespace shadel {

Scene loadScene(const std::string& spec, const SceneFileOptions& options,
                const BuiltinSceneOptions& builtin) {
    static const std::string builtinPrefix = "builtin:";
    if (spec.rfind(builtinPrefix, 0) == 0)
        return makeBuiltinScene(spec.substr(builtinPrefix.size()), builtin);
    if (builtin.instances != 0)
        throw InputError(spec + ": --instances applies only to builtin:many");
    if (spec.empty()) throw InputError("scene: empty scene name");
    std::string ext = std::filesystem::path(spec).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (ext != ".gltf" && ext != ".glb")
        throw InputError(spec +
                         ": unknown scene format (expected builtin:NAME, a .gltf or a .glb file)");
    return importGltf(spec, options);
}

} // namespace shadel
