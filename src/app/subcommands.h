#pragma once
// The subcommands of `shadel`, one file each (render_cli.cpp, bench_cli.cpp, view_cli.cpp,
// bake_cli.cpp, info_cli.cpp, cache_cli.cpp): each adds its flags to the app and returns what
// runs when it is the one chosen; main.cpp only parses and dispatches.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "rhi/device.h"
#include "rhi/frame.h"
#include "rhi/gpu.h"

namespace shadel {

// The flags before (or after) any subcommand.
struct GlobalFlags {
    std::string device = "auto";
    bool validation = false, verbose = false;
    bool allowExternalFiles = false; // glTF URIs may leave the model's folder
    std::string cacheLimit = "4G";
    uint64_t cacheLimitBytes = 0; // cacheLimit, parsed
    // The device's pipeline cache file in the cache folder (rhi/pipeline_cache.h): on | off
    // (or SHADEL_PIPELINE_CACHE=off), off for cold pipeline compiles.
    std::string pipelineCache = "on";
    // --load-memory-limit: what loading a scene may allocate ("": scene/load_budget.h's default).
    std::string loadMemoryLimit;
    // --device and --validation (or SHADEL_VALIDATION=1).
    DeviceDesc deviceDesc() const;
    // The bake cache's folder, or "" when --pipeline-cache off or SHADEL_PIPELINE_CACHE=off.
    std::string pipelineCacheFolder() const;
};
void addGlobalFlags(CLI::App& app, GlobalFlags& flags);

struct Subcommand {
    CLI::App* app = nullptr;
    // The exit code; bad input throws InputError, a device problem DeviceError.
    std::function<int(const GlobalFlags&)> run;
};
Subcommand addRenderCommand(CLI::App& app);
Subcommand addBenchCommand(CLI::App& app);
Subcommand addViewCommand(CLI::App& app);
Subcommand addBakeCommand(CLI::App& app);
Subcommand addInfoCommand(CLI::App& app);
Subcommand addCacheCommand(CLI::App& app);

// The parsers of flags more than one subcommand takes; InputError naming the flag otherwise.
float parseDensity(const std::string& text);                    // auto -> 0, else shadels per metre
uint32_t parseThreads(const std::string& text);                 // auto -> 0, else 1..64
std::optional<TimingMode> parseTiming(const std::string& text); // auto -> unset

// A device for one command, destroyed with it.
struct GpuGuard {
    explicit GpuGuard(const GlobalFlags& flags);
    ~GpuGuard();
    Gpu gpu;
};

} // namespace shadel
