#pragma once
// Which glTF extensions the importer understands, and the one rule for the others: a required
// extension we do not support makes the file unreadable (InputError naming it, exit 2); an
// optional one is ignored with one warning that lists every ignored extension once.
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace shadel {

// True for the extensions the importer applies (see the table in the README).
bool gltfExtensionSupported(std::string_view name);

// Throws InputError "<input>: required extension X is not supported" for the first entry of
// extensionsRequired that is not supported. Call after the schema check (it reads strings only).
void checkRequiredGltfExtensions(const nlohmann::json& root, const std::string& input);

// The unsupported extensions the file uses (extensionsUsed and every "extensions" object of the
// root, nodes, meshes' primitives, materials and their texture infos, textures, images,
// accessors, buffer views, buffers, cameras), sorted, each once. Linear in the document.
std::vector<std::string> ignoredGltfExtensions(const nlohmann::json& root);

// The warning line for them ("" when none), e.g. "extensions not supported, ignored (the scene
// may look different): A, B".
std::string ignoredExtensionsWarning(const std::vector<std::string>& ignored);

} // namespace shadel
