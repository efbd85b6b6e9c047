#pragma once
// Hot shader reload (rapid iterations): watches a GLSL source folder (the project's
// shaders/ or a copy), recompiles a stage when it or anything it includes
// changes, and swaps every pipeline built from that stage without touching the techniques that
// own them: bind() looks the pipeline's replacement up. A stage that fails to compile keeps
// its last good pipeline; the error (with its file and line) is returned and logged.
// The stage is compiled by the glslc the build uses, as a child process: Debian 12's
// libshaderc.so needs glslang from the program, and linking glslang-dev 12.0.0's static
// libraries made libshaderc crash (spv::Builder::getStringId), so libshaderc is not used.
#include <map>
#include <string>
#include <vector>

#include "rhi/pipeline.h"

namespace shadel {

struct Gpu;

struct ShaderReloadResult {
    std::vector<std::string> stagesRecompiled; // "forward/forward.frag"
    uint32_t pipelinesSwapped = 0;
    std::vector<std::string> errors; // "post/tonemap.comp:27: error: ..."
};

// Pipelines created after this call are recorded and can be rebuilt. `sourceDir` holds the
// GLSL tree the build compiled (shaders/): includes resolve against it.
void enableShaderHotReload(Gpu& gpu, const std::string& sourceDir);
// Destroys the replacements (call after the pipelines' owners destroyed them, or before).
void disableShaderHotReload(Gpu& gpu);
// Checks the files' times and sizes; recompiles and swaps what changed. Waits for the device
// to idle before destroying a replaced pipeline.
ShaderReloadResult pollShaderReload(Gpu& gpu);

// Used by rhi/pipeline.cpp.
void recordPipeline(Gpu& gpu, const Pipeline& pipeline, const GraphicsPipelineDesc* graphics,
                    const std::string& computeShader,
                    const std::vector<std::pair<uint32_t, uint32_t>>& specialization);
VkPipeline currentPipeline(const Gpu& gpu, VkPipeline original);
void forgetPipeline(Gpu& gpu, VkPipeline original);
// The newest good SPIR-V of a stage file ("forward_forward.frag.spv"), or empty.
const std::vector<uint32_t>* reloadedSpirv(const Gpu& gpu, const std::string& spvName);

} // namespace shadel
