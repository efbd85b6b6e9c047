// `shadel cache [clean]`: the bake cache's folder and size, and removing it
// (app/cache_command.h).
#include <memory>

#include "app/cache_command.h"
#include "app/commands.h"
#include "app/subcommands.h"

namespace shadel {

Subcommand addCacheCommand(CLI::App& app) {
    auto dir = std::make_shared<std::string>();
    CLI::App* c = app.add_subcommand("cache", "show the cache folder, its size per kind of file");
    c->add_option("--cache-dir", *dir, "cache folder");
    CLI::App* clean = c->add_subcommand("clean", "remove every cache file");
    clean->fallthrough(); // `shadel cache clean --cache-dir DIR`
    return {c, [dir, clean](const GlobalFlags& g) {
                return runCacheCommand(dir->empty() ? defaultCacheFolder() : *dir, bool(*clean),
                                       g.cacheLimitBytes);
            }};
}

} // namespace shadel
