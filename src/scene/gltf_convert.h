#pragma once
// The glTF importer's third gate: a loaded tinygltf model into the plain scene model (materials,
// meshes, the node hierarchy flattened to instances, skins, cameras, lights). It bounds-checks
// every accessor it reads and every index; every failure throws InputError "<input>: <reason>".
#include <string>

#include <tiny_gltf.h>

#include "scene/scene.h"

namespace shadel::gltf {

// `skinning`: skinned meshes are posed by their joints (with --time); otherwise drawn in their
// bind pose. `addDefaultSun`: a file without a directional light gets "auto-sun" (--sun auto).
void convertModel(const tinygltf::Model& model, const std::string& input, Scene& scene,
                  bool skinning, bool addDefaultSun);

} // namespace shadel::gltf
