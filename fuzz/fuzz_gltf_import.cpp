// libFuzzer target: the input is a .gltf or .glb file's contents. Every input must either import
// or throw InputError ("<file>: <reason>"); a crash, a sanitizer report, an uncaught exception
// of another type, a hang (-timeout) or runaway memory (-rss_limit_mb) is a finding.
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
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        shadel::importGltfBytes(std::vector<uint8_t>(data, data + size), modelPath());
    } catch (const shadel::InputError&) {
        // The expected outcome for malformed input.
    }
    return 0;
}
