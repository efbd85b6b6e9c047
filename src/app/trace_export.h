#pragma once
// --trace FILE.json: the frames of a run as Chrome trace events (chrome://tracing, Perfetto):
// one track for the CPU (frame, frontend), one for the GPU passes, named as in --passes, and
// in threaded frames one per recording worker (its passes' recording, with its CPU time).
#include <vector>

#include <nlohmann/json.hpp>

#include "render/renderer.h"

namespace shadel {

nlohmann::json chromeTrace(const std::vector<FrameResult>& frames, const std::string& label);

} // namespace shadel
