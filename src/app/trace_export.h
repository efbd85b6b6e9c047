#pragma once
// --trace FILE.json: the frames of a run as Chrome trace events (chrome://tracing, Perfetto):
// one track for the CPU (frame, frontend) and one for the GPU passes, named as in --passes.
#include <vector>

#include <nlohmann/json.hpp>

#include "render/renderer.h"

namespace shadel {

nlohmann::json chromeTrace(const std::vector<FrameResult>& frames, const std::string& label);

} // namespace shadel
