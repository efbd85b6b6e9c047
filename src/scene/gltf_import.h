#pragma once
// glTF 2.0 import (.gltf and .glb) into the plain scene model.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace shadel {

struct SceneFileOptions {
    // Buffer and image URIs may resolve outside the model's folder (`../`, absolute paths).
    bool allowExternalFiles = false;
    // --time: animations posed at this time in seconds (node TRS and morph weights); unset =
    // the file's rest pose.
    std::optional<double> time;
    // --sun auto|off: a file without a directional light gets a default sun (auto), or none.
    bool addDefaultSun = true;
};

// Loads a glTF 2.0 file. Every malformed input throws InputError with one line
// "<path>: <reason>"; recoverable problems (unsupported extensions, missing images, repaired
// normals) are logged as warnings and the import continues.
//
// The node hierarchy is flattened to instances with world transforms; a primitive becomes one
// Mesh (split into parts of at most kMaxTrianglesPerMesh triangles). A file without cameras
// gets an "auto" camera framing the scene, one without lights an "auto-sun".
Scene importGltf(const std::string& path, const SceneFileOptions& options = {});

// The same for the file's contents already in memory (the fuzz target): `path` names the input
// in errors and its folder is where buffer and image URIs resolve.
Scene importGltfBytes(std::vector<uint8_t> bytes, const std::string& path,
                      const SceneFileOptions& options = {});

} // namespace shadel
