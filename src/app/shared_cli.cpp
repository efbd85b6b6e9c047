// What more than one subcommand of `shadel` shares: the global flags, the device, and the
// parsers of flags several subcommands take (app/subcommands.h).
#include <cmath>
#include <cstdlib>

#include "app/cli_validate.h"
#include "app/subcommands.h"
#include "bake/bake_cache.h"
#include "bake/cache_eviction.h"
#include "bake/cache_folder.h"
#include "core/error.h"
#include "core/log.h"
#include "rhi/pipeline_cache.h"

namespace shadel {

void addGlobalFlags(CLI::App& app, GlobalFlags& f) {
    app.add_option("--device", f.device, "auto | cpu | gpu | INDEX")->capture_default_str();
    app.add_flag("--validation", f.validation,
                 "enable the Khronos validation layer (or SHADEL_VALIDATION=1)");
    app.add_flag("-v,--verbose", f.verbose, "debug logging");
    app.add_flag("--allow-external-files", f.allowExternalFiles,
                 "let glTF buffer/image URIs point outside the model's folder");
    app.add_option("--cache-limit", f.cacheLimit,
                   "bake cache size; least recently used files beyond it are removed (0 = none)")
        ->capture_default_str()
        ->check(byteSize());
    app.add_option("--load-memory-limit", f.loadMemoryLimit,
                   "memory a scene load may allocate (e.g. 8G; default: a quarter of RAM, at "
                   "most 2G)")
        ->check(byteSize());
    app.add_option("--pipeline-cache", f.pipelineCache,
                   "keep compiled pipelines in the cache folder between runs: on | off "
                   "(or SHADEL_PIPELINE_CACHE=off)")
        ->capture_default_str()
        ->check(CLI::IsMember({"on", "off"}));
}

DeviceDesc GlobalFlags::deviceDesc() const {
    DeviceDesc d;
    d.selection = device;
    const char* env = std::getenv("SHADEL_VALIDATION");
    d.validation = validation || (env && std::string(env) == "1");
    return d;
}

std::string GlobalFlags::pipelineCacheFolder() const {
    const char* env = std::getenv("SHADEL_PIPELINE_CACHE");
    bool off = pipelineCache == "off" || (env && std::string(env) == "off");
    return off ? std::string() : usableCacheFolder("");
}

GpuGuard::GpuGuard(const GlobalFlags& flags) {
    createGpu(gpu, flags.deviceDesc());
    if (std::string folder = flags.pipelineCacheFolder(); !folder.empty())
        keepPipelineCacheIn(gpu, folder);
}

GpuGuard::~GpuGuard() {
    destroyGpu(gpu);
}

float parseDensity(const std::string& t) {
    if (t == "auto") return 0.0f;
    char* end = nullptr;
    double v = std::strtod(t.c_str(), &end);
    if (end == t.c_str() || *end != '\0' || !(v > 0) || !std::isfinite(v) || v > 1e9)
        throw InputError(format(
            "--density %s: expected auto or a positive number of shadels per metre", t.c_str()));
    return float(v);
}

uint32_t parseThreads(const std::string& t) {
    if (t == "auto") return 0;
    char* end = nullptr;
    long v = std::strtol(t.c_str(), &end, 10);
    if (end == t.c_str() || *end != '\0' || v < 1 || v > 64)
        throw InputError(format("--threads %s: expected auto or 1..64", t.c_str()));
    return uint32_t(v);
}

std::optional<TimingMode> parseTiming(const std::string& t) {
    if (t == "auto") return std::nullopt;
    if (t == "timestamps") return TimingMode::Timestamps;
    if (t == "submit") return TimingMode::SubmitPerPass;
    throw InputError(format("--timing %s: expected auto, timestamps or submit", t.c_str()));
}

} // namespace shadel
