#pragma once
// One shared lavapipe device for all GPU tests, with the Khronos validation layer on.
// Every test checks afterwards that no validation error and no shader assert happened.
#include <gtest/gtest.h>

#include "app/commands.h"
#include "rhi/gpu.h"

namespace shadel::test {

Gpu& sharedGpu();
uint32_t validationErrors();

// Renders and returns the run; asserts no validation errors / shader asserts were added.
RenderRun renderChecked(const RenderOptions& options);

double psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b);

} // namespace shadel::test
