// `shadel cache [clean]`: the bake cache's folder and size, and removing it
// (app/cache_command.h).
#include <memory>

#include "app/cache_command.h"
#include "app/commands.h"
#include "app/subcommands.h"

namespace shadel {

Subcommand addCacheCommand(CLI::App& app) {
    auto dir = std::make_shared<std::string>();
    CLI::App* c = app.add_subcommand("cache", "show the bake cache's folder and size");
    c->add_option("--cache-dir", *dir, "bake cache directory");
    CLI::App* clean = c->add_subcommand("clean", "remove every bake cache file");
    clean->fallthrough(); // `shadel cache clean --cache-dir DIR`
    return {c, [dir, clean](const GlobalFlags& g) {
                return runCacheCommand(dir->empty() ? defaultCacheDir() : *dir, bool(*clean),
                                       g.cacheLimitBytes);
            }};
}

} // namespace shadel
