// bench --environment-compare: what image-based lighting costs. The same frames forward and
// decoupled, lit by the built-in sky (the environment's diffuse, specular, sheen and clear-coat
// lookups in every shaded sample, and the sky behind the scene) and with --environment none
// (those lookups return at once; the background pass still runs and draws black). --rounds
// rounds, the four runs in turn within each; ratios are sky / none of the median frame time,
// the median over the rounds.
#include <cstdio>
#include <vector>

#include "app/commands.h"
#include "app/output_files.h"
#include "app/stats_schema.h"

namespace shadel {

nlohmann::json runEnvironmentBench(Gpu& gpu, const BenchOptions& b, RenderOptions o) {
    nlohmann::json out;
    out["scene"] = b.scene;
    recordDevice(out, gpu);
    out["frames"] = b.frames;
    out["rounds"] = b.rounds;
    o.environmentGiven = true;
    struct Run {
        const char* name;
        RenderMode mode;
        const char* environment;
        std::vector<double> frameMs;
    };
    std::vector<Run> runs = {{"forward_sky", RenderMode::Forward, "builtin:sky", {}},
                             {"forward_none", RenderMode::Forward, "none", {}},
                             {"decoupled_sky", RenderMode::Decoupled, "builtin:sky", {}},
                             {"decoupled_none", RenderMode::Decoupled, "none", {}}};
    {
        // The first frame of a process pays for pipeline creation and first-touch memory.
        RenderOptions warm = o;
        warm.frames = 1;
        warm.environment = "builtin:sky";
        std::fprintf(stderr, "bench: warm-up frame\n");
        runRender(gpu, warm);
    }
    std::vector<double> forwardRatios, decoupledRatios;
    for (uint32_t round = 0; round < b.rounds; ++round) {
        for (size_t k = 0; k < runs.size(); ++k) {
            // Alternate the order between rounds, so that drift reaches each run alike.
            Run& r = runs[round % 2 == 0 ? k : runs.size() - 1 - k];
            std::fprintf(stderr, "bench: round %u/%u, %s, %u frames at %ux%u\n", round + 1,
                         b.rounds, r.name, b.frames, b.width, b.height);
            o.mode = r.mode;
            o.environment = r.environment;
            RenderRun run = runRender(gpu, o);
            r.frameMs.push_back(run.stats["frame_ms"]["median"].get<double>());
            out["modes"][r.name] = std::move(run.stats);
        }
        auto last = [&](size_t k) { return runs[k].frameMs.back(); };
        forwardRatios.push_back(last(1) > 0 ? last(0) / last(1) : 0.0);
        decoupledRatios.push_back(last(3) > 0 ? last(2) / last(3) : 0.0);
    }
    for (Run& r : runs) out["frame_ms_median_of_rounds"][r.name] = median(r.frameMs);
    out["ratios"]["environment_forward"] = median(forwardRatios);
    out["ratios"]["environment_decoupled"] = median(decoupledRatios);
    std::printf("shadel bench --environment-compare: %s at %ux%u on %s, %u frames x %u rounds, "
                "median frame times\n",
                b.scene.c_str(), b.width, b.height, deviceLabel(gpu).c_str(), b.frames, b.rounds);
    std::printf("  %-10s %12s %12s %8s\n", "", "builtin:sky", "none", "ratio");
    for (int m = 0; m < 2; ++m) {
        double sky = median(runs[2 * m].frameMs), none = median(runs[2 * m + 1].frameMs);
        std::printf("  %-10s %9.3f ms %9.3f ms %8.3f\n", m == 0 ? "forward" : "decoupled", sky,
                    none, median(m == 0 ? forwardRatios : decoupledRatios));
    }
    writeBenchJson(b.json, out);
    return out;
}

} // namespace shadel
