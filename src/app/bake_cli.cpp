// `shadel bake`: shadel charts and triangle-ID maps of a scene, into the bake cache.
#include <chrono>
#include <cstdio>
#include <memory>
#include <unistd.h>

#include "app/cli_validate.h"
#include "app/commands.h"
#include "app/subcommands.h"
#include "bake/bake.h"
#include "core/log.h"
#include "scene/load.h"

namespace shadel {
namespace {

struct BakeFlags {
    std::string scene = "builtin:default", cacheDir;
    float density = 32.0f;
    bool noCache = false;
    double budget = 64e6;
};

int runBakeCommand(const BakeFlags& f, const GlobalFlags& g) {
    Scene scene = loadScene(f.scene, {.allowExternalFiles = g.allowExternalFiles});
    BakeSettings bs;
    bs.cacheLimitBytes = g.cacheLimitBytes;
    double area = 0.0;
    bs.shadelsPerMetre = sceneShadelDensity(scene, f.density, f.budget, area);
    if (bs.shadelsPerMetre < f.density)
        SHADEL_WARN("%s: %.0f units^2 of surface: using %.3f shadels/unit to stay within %.0fM "
                    "shadels",
                    f.scene.c_str(), area, double(bs.shadelsPerMetre), f.budget / 1e6);
    std::string dir = f.noCache ? "" : usableCacheFolder(f.cacheDir);
    bool tty = isatty(STDERR_FILENO);
    auto start = std::chrono::steady_clock::now();
    auto baked = bakeScene(scene, bs, dir, [&](size_t done, size_t total) {
        if (tty) {
            int width = 40, filled = total ? int(width * done / total) : width;
            std::fprintf(stderr, "\rbake: [%s%s] %zu/%zu meshes", std::string(filled, '#').c_str(),
                         std::string(width - filled, '.').c_str(), done, total);
        } else if (done == total || done % 16 == 0) {
            std::fprintf(stderr, "bake: %zu/%zu meshes\n", done, total);
        }
    });
    if (tty) std::fprintf(stderr, "\n");
    double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("%s", bakeReport(baked, seconds).c_str());
    return 0;
}

} // namespace

Subcommand addBakeCommand(CLI::App& app) {
    auto f = std::make_shared<BakeFlags>();
    CLI::App* c = app.add_subcommand("bake", "bake shadel charts and triangle-ID maps (cached)");
    c->add_option("scene", f->scene, "builtin:NAME | FILE.gltf | FILE.glb")->capture_default_str();
    c->add_option("--density", f->density, "shadels per metre")
        ->capture_default_str()
        ->check(finiteInRange(kFixedDensityRange));
    c->add_option("--cache-dir", f->cacheDir, "bake cache directory");
    c->add_option("--shadel-budget", f->budget,
                  "max MIP-0 shadels for the scene (lowers --density)")
        ->capture_default_str()
        ->check(finiteInRange(kShadelBudgetRange));
    c->add_flag("--no-cache", f->noCache, "bake from scratch (still writes the cache)");
    return {c, [f](const GlobalFlags& g) { return runBakeCommand(*f, g); }};
}

} // namespace shadel
