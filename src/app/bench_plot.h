#pragma once
// `shadel bench --plot FILE.png`: the per-pass comparison as a grouped bar chart (one group per
// pass, one bar per mode, GPU ms), drawn on the CPU; text uses Dear ImGui's built-in font atlas.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace shadel {

struct PlotImage {
    uint32_t width = 0, height = 0;
    std::vector<uint8_t> rgba;
};

// The colour of each mode's bars (forward, decoupled, reuse), for the legend and the tests.
extern const uint8_t kPlotModeColours[3][3];

// `bench` is runBench's result (modes.forward|decoupled|reuse with their passes).
PlotImage plotBench(const nlohmann::json& bench);
void writeBenchPlot(const nlohmann::json& bench, const std::string& path);

} // namespace shadel
