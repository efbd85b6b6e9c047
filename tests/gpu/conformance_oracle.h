#pragma once
// The glTF Sample Viewer's images as an oracle (tools/conformance/models.json): a model staged
// with its resources, rendered by shadel as the viewer rendered it, and measured against the
// viewer's image. Used by the conformance suite and by tests that compare a feature's on and off
// renders with the same reference.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gpu_test_env.h"

namespace shadel::test {

const nlohmann::json& conformanceManifest();
// The manifest's entry named `name` (null when absent).
nlohmann::json conformanceModel(const std::string& name);

// The model's own folder and, for wrappers of sample models, its resources folder, linked into
// one scratch folder; returns the model file's path there.
std::filesystem::path stageConformanceModel(const nlohmann::json& model);

// The viewer's image of a model, re-encoded with the sRGB curve (empty when missing).
std::vector<uint8_t> loadConformanceReference(const std::string& name, int& w, int& h);

// shadel's straight-alpha pixels composited over black, as the reference holds them.
void compositeOverBlack(std::vector<uint8_t>& rgba);

struct ConformanceMeasure {
    double psnr = 0.0;
    size_t covered = 0;        // pixels either image covers
    size_t shadelCovered = 0;  // pixels shadel covers
    double shadelStdDev = 0.0; // of shadel's luma over its covered pixels (8-bit levels)
};
ConformanceMeasure measureAgainstReference(const std::vector<uint8_t>& ref,
                                           const std::vector<uint8_t>& img);

// The reference's view: the file's camera and light, the manifest's environment, tonemap and
// supersampling, no shadows, a black background.
RenderOptions conformanceOptions(const std::string& scene, RenderMode mode, uint32_t w, uint32_t h);

} // namespace shadel::test
