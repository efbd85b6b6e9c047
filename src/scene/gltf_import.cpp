// glTF 2.0 import. The file goes through three gates before anything is built from it:
//  1. our own structural check of the raw JSON (types, index ranges, buffer-view ranges, version:
//     gltf_checks.h), because tinygltf silently ignores wrongly typed optional properties and
//     trusts the ranges it later slices image data with;
//  2. tinygltf, which resolves buffers (files, data URIs, the GLB chunk) and images through the
//     callbacks of gltf_files.h;
//  3. the conversion (gltf_convert.h), which bounds-checks every accessor it reads
//     (gltf_accessors.h) and every index.
// Every failure is an InputError "<file>: <reason>"; nothing is read out of bounds.
//
// This translation unit also holds the one definition of tinygltf, stb_image and
// stb_image_write in the project (the PNG writer includes <stb/stb_image_write.h> without
// STB_IMAGE_WRITE_IMPLEMENTATION).

#include "scene/gltf_import.h"

#include <filesystem>

#include <nlohmann/json.hpp>

// Images larger than this are rejected by stb_image itself (before it allocates).
#define STBI_MAX_DIMENSIONS 16384
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

// Declares tinygltf's types first (tiny_gltf.h guards its declarations, not its implementation).
#include "scene/gltf_animation.h"
#include "scene/gltf_convert.h"
#include "scene/gltf_files.h"
#include "scene/gltf_meshopt.h"

#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_INCLUDE_STB_IMAGE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE_WRITE
#include <tiny_gltf.h>

#include "core/error.h"
#include "core/log.h"
#include "scene/gltf_checks.h"
#include "scene/gltf_extensions.h"
#include "scene/load_budget.h"

namespace shadel {

using namespace gltf;
using json = nlohmann::json;

Scene importGltf(const std::string& path, const SceneFileOptions& options) {
    return importGltfBytes(readWholeFile(path, path), path, options);
}

Scene importGltfBytes(std::vector<uint8_t> bytes, const std::string& path,
                      const SceneFileOptions& options) {
    const std::string& input = path;
    if (bytes.size() > kMaxFileBytes) fail(input, "file is larger than the size limit");
    LoadBudgetScope budget(input);
    chargeLoadMemory(bytes.size() * 2, "the file and its parsed copy");
    bool binary = bytes.size() >= 4 && readU32(bytes.data()) == kGlbMagic;

    json document = parseJson(jsonTextOf(bytes, binary, input), input);
    checkCounts(document, input);
    checkSchema(document, input);
    checkRequiredGltfExtensions(document, input);
    std::string extensionsWarning = ignoredExtensionsWarning(ignoredGltfExtensions(document));
    if (!options.allowExternalFiles) checkUrisStayInFolder(document, input);
    MeshoptPlan meshopt = prepareMeshopt(document, input);
    if (!meshopt.fallbacks.empty()) bytes = withJsonText(bytes, binary, document.dump());
    document = json(); // tinygltf parses its own copy

    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(decodeImageToRgba8, nullptr);
    std::string baseDir = std::filesystem::path(path).parent_path().string();
    FileAccess access{baseDir, options.allowExternalFiles};
    loader.SetFsCallbacks({fsFileExists, fsExpandPath, fsReadWholeFile, fsWriteWholeFile, &access});
    tinygltf::Model model;
    std::string err, warn;
    bool ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(),
                                                   unsigned(bytes.size()), baseDir)
                     : loader.LoadASCIIFromString(&model, &err, &warn,
                                                  reinterpret_cast<const char*>(bytes.data()),
                                                  unsigned(bytes.size()), baseDir);
    if (!warn.empty()) {
        size_t start = 0;
        while (start < warn.size()) {
            size_t end = warn.find('\n', start);
            if (end == std::string::npos) end = warn.size();
            if (end > start)
                SHADEL_WARN("%s: %s", input.c_str(), warn.substr(start, end - start).c_str());
            start = end + 1;
        }
    }
    if (!ok || !err.empty()) fail(input, oneLine(err.empty() ? "glTF loader failed" : err));
    decodeMeshopt(meshopt, model, input);
    if (options.time)
        poseAnimations(model, *options.time, input,
                       [&](const std::string& w) { SHADEL_WARN("%s", w.c_str()); });
    bytes.clear();
    bytes.shrink_to_fit();

    Scene scene;
    scene.name = std::filesystem::path(path).stem().string();
    if (!extensionsWarning.empty()) SHADEL_WARN("%s: %s", input.c_str(), extensionsWarning.c_str());
    convertModel(model, input, scene, options.time.has_value(), options.addDefaultSun);
    return scene;
}

} // namespace shadel
