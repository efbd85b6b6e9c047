#pragma once
// --trace FILE.json: the frames of a run as Chrome trace events (chrome://tracing, Perfetto):
// one track for the CPU (frame, frontend, finer scopes), in threaded frames one per recording
// worker (its passes' recording, with its CPU time), and the GPU passes, named as in --passes,
// in a process of their own named "GPU". Every slice lies within its parent on its track.
#include <vector>

#include <nlohmann/json.hpp>

#include "render/renderer.h"

namespace shadel {

nlohmann::json chromeTrace(const std::vector<FrameResult>& frames, const std::string& label);

} // namespace shadel
