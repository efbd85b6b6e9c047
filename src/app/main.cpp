// `shadel`: render, bench, view, bake, info, cache (one file each: app/subcommands.h). Errors:
// one line on stderr naming the input and the reason; exit 2 for bad input, 3 for a device
// problem, 1 for anything else.
#include <cstdio>
#include <new>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/cli_help.h"
#include "app/cli_validate.h"
#include "app/subcommands.h"
#include "bake/cache_eviction.h"
#include "core/error.h"
#include "core/log.h"
#include "scene/load_budget.h"

using namespace shadel;

int main(int argc, char** argv) {
    CLI::App app{"shadel: a Vulkan renderer built around generalized decoupled shading"};
    app.require_subcommand(1);
    GlobalFlags global;
    addGlobalFlags(app, global);
    app.set_version_flag("--version", "shadel 0.1.0: decoupled shading on Vulkan 1.3");
    const std::vector<Subcommand> subcommands = {addRenderCommand(app), addBenchCommand(app),
                                                 addBakeCommand(app),   addViewCommand(app),
                                                 addInfoCommand(app),   addCacheCommand(app)};
    showGlobalFlagsInSubcommandHelp(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return exitForParseError(app, e);
    }
    parseByteSize(global.cacheLimit, global.cacheLimitBytes); // validated by byteSize()
    if (!global.loadMemoryLimit.empty()) {
        uint64_t bytes = 0;
        parseByteSize(global.loadMemoryLimit, bytes); // validated by byteSize()
        setLoadMemoryLimit(bytes);
    }
    if (global.verbose) setLogLevel(LogLevel::Debug);
    try {
        for (const Subcommand& sub : subcommands)
            if (*sub.app) return sub.run(global);
    } catch (const InputError& e) {
        std::fprintf(stderr, "shadel: %s\n", e.what());
        return kExitBadInput;
    } catch (const std::bad_alloc&) {
        // A load's budget (scene/load_budget.h) stops what it can foresee; anything else that
        // outgrows memory is still one line and a bad-input exit, never an abort.
        std::fprintf(stderr, "shadel: out of memory (a larger input than this machine can hold; "
                             "see --load-memory-limit)\n");
        return kExitBadInput;
    } catch (const DeviceError& e) {
        std::fprintf(stderr, "shadel: device: %s\n", e.what());
        return 3;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "shadel: %s\n", e.what());
        return 1;
    }
    return 0;
}
