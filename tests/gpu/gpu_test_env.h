#pragma once
// One shared lavapipe device for all GPU tests, with the Khronos validation layer on.
// Every test checks afterwards that no validation error and no shader assert happened.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "rhi/gpu.h"

namespace shadel::test {

Gpu& sharedGpu();
uint32_t validationErrors();

// Renders and returns the run; asserts no validation errors / shader asserts were added.
RenderRun renderChecked(const RenderOptions& options);

double psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b);

// Options for rendering `scene` in `mode` at w x h (everything else default).
RenderOptions renderOptions(const std::string& scene, RenderMode mode, uint32_t w, uint32_t h);

// A path in the temp directory private to this test process (`name` prefixed with the pid), so
// two test runs on one machine never read each other's files.
std::string tempPath(const std::string& name);

// Flicker: mean absolute difference between consecutive frames, over all colour channels.
double meanFrameDelta(const RenderRun& run);

// The JSON a run wrote to `path` (a --trace file), then the file removed; null if it is missing.
nlohmann::json takeJsonFile(const std::string& path);

// The lowest PSNR between the runs' frames of the same index (the runs have as many frames).
double worstFramePsnr(const RenderRun& a, const RenderRun& b);

} // namespace shadel::test
