// libFuzzer target: the input is a .gltf or .glb file's contents. Every input must either import
// into a scene that keeps the engine's invariants (sceneInvariantViolation: indices in range,
// finite positions and transforms, unit normals, materials and textures that exist...) or throw
// InputError ("<file>: <reason>"); a crash, a sanitizer report, an uncaught exception of another
// type, a broken invariant, a hang (-timeout) or runaway memory (-rss_limit_mb) is a finding.
//
// Buffer and image URIs resolve in an empty private folder, so inputs cannot reach other files
// (URIs escaping it are refused by the importer itself).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

#include "core/error.h"
#include "core/log.h"
#include "scene/gltf_import.h"
#include "scene/load_budget.h"
#include "scene/mesh_utils.h"

namespace {

std::string modelPath() {
    static const std::string path = [] {
        auto folder = std::filesystem::temp_directory_path() /
                      ("shadel-fuzz-gltf-" + std::to_string(getpid()));
        std::filesystem::create_directories(folder);
        static const std::filesystem::path removeAtExit = folder;
        std::atexit([] {
            std::error_code ec;
            std::filesystem::remove_all(removeAtExit, ec);
        });
        return (folder / "input.gltf").string();
    }();
    return path;
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    shadel::setLogLevel(shadel::LogLevel::Error); // warnings for every input would drown it
    // Well under -rss_limit_mb: an input that expands past the load budget is an InputError.
    shadel::setLoadMemoryLimit(512ull << 20);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    shadel::Scene scene;
    try {
        scene = shadel::importGltfBytes(std::vector<uint8_t>(data, data + size), modelPath());
    } catch (const shadel::InputError&) {
        return 0; // the expected outcome for malformed input
    }
    if (std::string broken = shadel::sceneInvariantViolation(scene); !broken.empty()) {
        std::fprintf(stderr, "accepted input breaks a scene invariant: %s\n", broken.c_str());
        std::abort(); // a finding: libFuzzer saves the input
    }
    return 0;
}
