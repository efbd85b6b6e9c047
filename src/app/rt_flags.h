#pragma once
// The ray-tracing flags of `shadel render` (render/raytracing): --rt-shadows|ao|gi on|off,
// --rays-per-shadel, --rt-distance, --blas-pool-mb, --blas-pool-limit and the ray counts.
#include <string>

#include <CLI/CLI.hpp>

#include "render/raytracing/rt_settings.h"

namespace shadel {

struct RtFlags {
    std::string shadows = "off", ao = "off", gi = "off", filter = "on", animatedBlas = "on";
    RtSettings settings; // the numeric flags land here directly
};

void addRayTracingFlags(CLI::App& render, RtFlags& flags);
// Throws InputError naming the first bad flag.
RtSettings parseRayTracingFlags(const RtFlags& flags);

} // namespace shadel
