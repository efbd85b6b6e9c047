#pragma once
// Compute pipelines from SPIR-V compiled at run time (material program stages), kept in the
// device's library like those loaded from the build's shader directory. Shader hot reload does
// not watch them: their owner recompiles and recreates them.
#include <string>
#include <vector>

#include "rhi/pipeline.h"

namespace shadel {

Pipeline createComputePipelineFromSpirv(Gpu& gpu, const std::string& name,
                                        const std::vector<uint32_t>& code);

} // namespace shadel
