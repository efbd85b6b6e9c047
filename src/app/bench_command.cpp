#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <unistd.h>
#include <vector>

#include "app/bench_plot.h"
#include "app/cli_validate.h"
#include "app/commands.h"
#include "app/option_table.h"
#include "app/output_files.h"
#include "core/error.h"
#include "core/log.h"
#include "scene/builtin_scenes.h"

namespace shadel {

double passMs(const nlohmann::json& stats, const char* name) {
    for (const auto& p : stats["passes"])
        if (p["name"] == name) return p["gpu_ms"].get<double>();
    return 0.0;
}

namespace {

// The passes --spectra on and single differ in (bench --spectra compare): the shading the
// permutations replace plus spectra's own classify + bin work, so that its overhead is charged.
// Forward: the tile pass (light culling, which also classifies and bins each tile) and the tile
// shading; decoupled: the chunk classify + bin pass and the per-spectrum shadel shading.
const char* const kForwardSpectraPasses[] = {"lightCulling", "tileShading"};
const char* const kDecoupledSpectraPasses[] = {"shadelChunkSpectra", "shadelShading"};

// --particle-lighting-compare: the same forward frames with the particles lit through the
// atlas, per pixel and per vertex. The particle lighting cost of a mode is what its particle
// passes cost beyond the vertex-lit sprites (whose lighting is 4 evaluations per sprite):
// atlas = particleAtlasLighting + particleSprites - vertex's particleSprites, pixel =
// particleSprites - vertex's particleSprites. The total (atlas lighting + sprites against
// sprites) is reported too.
nlohmann::json runParticleLightingBench(Gpu& gpu, const BenchOptions& b, RenderOptions o) {
    nlohmann::json out;
    out["scene"] = b.scene;
    recordDevice(out, gpu);
    out["frames"] = b.frames;
    o.mode = RenderMode::Forward;
    const std::pair<const char*, ParticleLighting> modes[] = {{"atlas", ParticleLighting::Atlas},
                                                              {"pixel", ParticleLighting::Pixel},
                                                              {"vertex", ParticleLighting::Vertex}};
    for (const auto& [name, lighting] : modes) {
        std::fprintf(stderr, "bench: particle lighting %s, %u frames at %ux%u\n", name, b.frames,
                     b.width, b.height);
        o.particleLighting = lighting;
        out["modes"][name] = runRender(gpu, o).stats;
    }
    double atlasLight = passMs(out["modes"]["atlas"], "particleAtlasLighting");
    // The sprite pass is particleSpritesHalf at --particle-resolution half (the default).
    auto sprites = [&](const char* mode) {
        return passMs(out["modes"][mode], "particleSprites") +
               passMs(out["modes"][mode], "particleSpritesHalf");
    };
    double atlasSprites = sprites("atlas");
    double pixelSprites = sprites("pixel");
    double vertexSprites = sprites("vertex");
    double atlasLighting = atlasLight + atlasSprites - vertexSprites;
    double pixelLighting = pixelSprites - vertexSprites;
    out["particle_ms"] = {
        {"atlas_lighting_pass", atlasLight},    {"atlas_sprites", atlasSprites},
        {"pixel_sprites", pixelSprites},        {"vertex_sprites", vertexSprites},
        {"atlas_lighting_cost", atlasLighting}, {"pixel_lighting_cost", pixelLighting}};
    out["ratios"]["particle_lighting_atlas_over_pixel"] =
        pixelLighting > 0 ? atlasLighting / pixelLighting : 0.0;
    out["ratios"]["particle_total_atlas_over_pixel"] =
        pixelSprites > 0 ? (atlasLight + atlasSprites) / pixelSprites : 0.0;
    std::printf("shadel bench --particle-lighting-compare: %s at %ux%u on %s, %u frames, "
                "medians (timing: %s)\n",
                b.scene.c_str(), b.width, b.height, deviceLabel(gpu).c_str(), b.frames,
                out["modes"]["atlas"]["timing"].get<std::string>().c_str());
    std::printf("  particleAtlasLighting (atlas)  %10.3f ms\n", atlasLight);
    std::printf("  particleSprites atlas / pixel / vertex  %.3f / %.3f / %.3f ms\n", atlasSprites,
                pixelSprites, vertexSprites);
    std::printf("  lighting cost atlas %.3f ms / pixel %.3f ms = %.3f\n", atlasLighting,
                pixelLighting, out["ratios"]["particle_lighting_atlas_over_pixel"].get<double>());
    std::printf("  particle total atlas %.3f ms / pixel %.3f ms = %.3f\n",
                atlasLight + atlasSprites, pixelSprites,
                out["ratios"]["particle_total_atlas_over_pixel"].get<double>());
    if (!b.json.empty()) writeOutputFile(b.json, out.dump(2) + "\n");
    return out;
}

// --stencil-compare: the same forward frames with --screen-space on and the stencil effects,
// stencil-culled and full-screen (the same shaders on every pixel, branching per pixel). The
// ratio of each effect pass is culled / full-screen; the marks (stencilMark) are reported apart,
// and so is the unbounded stencil draw (one triangle over the whole target, the stencil test
// alone culling) the culled passes improve on by drawing only over their instances' rects.
nlohmann::json runStencilBench(Gpu& gpu, const BenchOptions& b, RenderOptions o) {
    nlohmann::json out;
    out["scene"] = b.scene;
    recordDevice(out, gpu);
    out["frames"] = b.frames;
    o.mode = RenderMode::Forward;
    o.screenSpace = true;
    for (auto [name, mode] : {std::pair{"stencil", StencilEffects::On},
                              std::pair{"stencil_unbounded", StencilEffects::OnUnbounded},
                              std::pair{"fullscreen", StencilEffects::FullScreen}}) {
        std::fprintf(stderr, "bench: stencil effects %s, %u frames at %ux%u\n", name, b.frames,
                     b.width, b.height);
        o.stencilEffects = mode;
        out["modes"][name] = runRender(gpu, o).stats;
    }
    const nlohmann::json& culled = out["modes"]["stencil"];
    const nlohmann::json& full = out["modes"]["fullscreen"];
    double outline = passMs(culled, "characterOutline");
    double outlineFull = passMs(full, "characterOutlineFullScreen");
    double water = passMs(culled, "waterComposite");
    double waterFull = passMs(full, "waterCompositeFullScreen");
    out["stencil_ms"] = {{"character_outline", outline},
                         {"character_outline_fullscreen", outlineFull},
                         {"water_composite", water},
                         {"water_composite_fullscreen", waterFull},
                         {"stencil_mark", passMs(culled, "stencilMark")}};
    const nlohmann::json& unbounded = out["modes"]["stencil_unbounded"];
    out["stencil_ms"]["character_outline_unbounded"] = passMs(unbounded, "characterOutline");
    out["stencil_ms"]["water_composite_unbounded"] = passMs(unbounded, "waterComposite");
    out["ratios"]["stencil_outline"] = outlineFull > 0 ? outline / outlineFull : 0.0;
    out["ratios"]["stencil_water"] = waterFull > 0 ? water / waterFull : 0.0;
    std::printf("shadel bench --stencil-compare: %s at %ux%u on %s, %u frames, medians (timing: "
                "%s)\n",
                b.scene.c_str(), b.width, b.height, deviceLabel(gpu).c_str(), b.frames,
                culled["timing"].get<std::string>().c_str());
    std::printf("  characterOutline  stencil %.3f ms / full-screen %.3f ms = %.3f\n", outline,
                outlineFull, out["ratios"]["stencil_outline"].get<double>());
    std::printf("  waterComposite    stencil %.3f ms / full-screen %.3f ms = %.3f\n", water,
                waterFull, out["ratios"]["stencil_water"].get<double>());
    std::printf("  unbounded stencil draws (whole target): characterOutline %.3f ms, "
                "waterComposite %.3f ms\n",
                out["stencil_ms"]["character_outline_unbounded"].get<double>(),
                out["stencil_ms"]["water_composite_unbounded"].get<double>());
    std::printf("  stencilMark (depth-stencil copy + marks) %.3f ms\n",
                out["stencil_ms"]["stencil_mark"].get<double>());
    if (!b.json.empty()) writeOutputFile(b.json, out.dump(2) + "\n");
    return out;
}

// What every bench run in interleaved rounds reports first.
static nlohmann::json roundsBenchHeader(const Gpu& gpu, const BenchOptions& b) {
    nlohmann::json out;
    out["scene"] = b.scene;
    recordDevice(out, gpu);
    out["frames"] = b.frames;
    out["rounds"] = b.rounds;
    out["size"] = format("%ux%u", b.width, b.height);
    return out;
}

// --streaming-compare: the same frames (forward and decoupled, reuse as --reuse-refresh says)
// with every texture resident, and streamed at --texture-budget through the layered cache and
// through sparse residency (when the device has it). The figure is the render thread's CPU time
// per frame (cpu_frame_thread_ms: the thread's own clock, so other processes taking the cores
// do not inflate it): the "no stalls" check is streaming / resident <= 1.10. The modes
// run in rounds, each round every residency once in a rotated order, so the machine's drift
// over the bench hits them alike; the median is over the frames of every round.
nlohmann::json runStreamingBench(Gpu& gpu, const BenchOptions& b, RenderOptions o) {
    nlohmann::json out = roundsBenchHeader(gpu, b);
    out["texture_budget_mib"] = b.textureBudgetMiB;
    o.galleryTextureSize = b.galleryTextureSize;
    struct Residency {
        const char* name;
        double budgetMiB;
        StreamingMode mode;
    };
    std::vector<Residency> residencies = {{"resident", 0.0, StreamingMode::Layered},
                                          {"layered", b.textureBudgetMiB, StreamingMode::Layered}};
    if (gpu.device.optional.sparseResidency) {
        // A one-frame probe: the sparse tails can need more than a small budget (lavapipe pages
        // every level down to 1x1, 28 MiB for the gallery), then the bench compares layered only.
        RenderOptions probe = o;
        probe.frames = 1;
        probe.width = probe.height = 16;
        probe.textureBudgetMiB = b.textureBudgetMiB;
        probe.streaming = StreamingMode::Sparse;
        try {
            runRender(gpu, probe);
            residencies.push_back({"sparse", b.textureBudgetMiB, StreamingMode::Sparse});
        } catch (const InputError& e) {
            SHADEL_WARN("bench --streaming-compare: sparse left out: %s", e.what());
        }
    } else {
        SHADEL_WARN("bench --streaming-compare: %s has no sparse residency; layered only",
                    gpu.device.name.c_str());
    }
    const std::pair<const char*, RenderMode> renderModes[] = {{"forward", RenderMode::Forward},
                                                              {"decoupled", RenderMode::Decoupled}};
    // Per render mode and residency: every round's frames, and the last round's stats.
    std::map<std::string, std::vector<double>> threadMs, streamingMs, frameMs;
    for (uint32_t round = 0; round < b.rounds; ++round) {
        for (const auto& [modeName, mode] : renderModes) {
            for (size_t k = 0; k < residencies.size(); ++k) {
                const Residency& res = residencies[(k + round) % residencies.size()];
                std::fprintf(stderr, "bench: round %u/%u, %s, %s, %u frames at %ux%u\n", round + 1,
                             b.rounds, modeName, res.name, b.frames, b.width, b.height);
                o.mode = mode;
                o.textureBudgetMiB = res.budgetMiB;
                o.streaming = res.mode;
                RenderRun run = runRender(gpu, o);
                if (!run.stats.contains("texture_streaming"))
                    throw InputError(format("bench --streaming-compare: %s has no textures to "
                                            "stream (try builtin:textures)",
                                            b.scene.c_str()));
                std::string key = std::string(modeName) + "_" + res.name;
                for (const FrameResult& f : run.frames) {
                    threadMs[key].push_back(f.cpuThreadMs);
                    streamingMs[key].push_back(f.cpuStreamingMs);
                    frameMs[key].push_back(f.frameMs);
                }
                // Per round (a round the machine slowed shows here) and per frame.
                nlohmann::json& row = out["streaming"][modeName][res.name];
                row["cpu_frame_thread_ms_per_round"].push_back(run.stats["cpu_frame_thread_ms"]);
                std::vector<double> frames;
                for (const FrameResult& f : run.frames) frames.push_back(f.cpuThreadMs);
                row["cpu_frame_thread_ms_per_frame"].push_back(frames);
                out["modes"][key] = std::move(run.stats);
            }
        }
    }
    std::printf("shadel bench --streaming-compare: %s at %ux%u on %s, %u frames x %u rounds, "
                "--texture-budget %g MiB, medians over every round's frames\n",
                b.scene.c_str(), b.width, b.height, deviceLabel(gpu).c_str(), b.frames, b.rounds,
                b.textureBudgetMiB);
    std::printf("  %-10s %-9s %16s %14s %10s %12s %14s  %s\n", "mode", "textures", "cpu thread ms",
                "of which strm", "ratio", "frame ms", "peak MiB", "cpu thread ms per round");
    for (const auto& [modeName, mode] : renderModes) {
        double residentMs = median(threadMs[std::string(modeName) + "_resident"]);
        for (const Residency& res : residencies) {
            std::string key = std::string(modeName) + "_" + res.name;
            double ms = median(threadMs[key]);
            double ratio = residentMs > 0 ? ms / residentMs : 0.0;
            nlohmann::json& row = out["streaming"][modeName][res.name];
            row["cpu_frame_thread_ms"] = ms;
            row["cpu_streaming_thread_ms"] = median(streamingMs[key]);
            row["frame_ms"] = median(frameMs[key]);
            row["texture_memory_peak_bytes"] = out["modes"][key]["texture_memory_peak_bytes"];
            if (res.budgetMiB > 0.0)
                out["ratios"][std::string("streaming_") + modeName + "_" + res.name] = ratio;
            std::string rounds;
            for (const auto& r : row["cpu_frame_thread_ms_per_round"])
                rounds += format(" %.3f", r.get<double>());
            std::printf("  %-10s %-9s %13.3f ms %11.3f ms %10.3f %9.1f ms %14.1f %s\n", modeName,
                        res.name, ms, row["cpu_streaming_thread_ms"].get<double>(), ratio,
                        row["frame_ms"].get<double>(),
                        double(row["texture_memory_peak_bytes"].get<uint64_t>()) / 1048576.0,
                        rounds.c_str());
        }
    }
    if (!b.json.empty()) writeOutputFile(b.json, out.dump(2) + "\n");
    return out;
}

// The row of a run's stats "cpu_scopes" named `name` (null when the run did not time it).
const nlohmann::json* cpuScopeRow(const nlohmann::json& stats, const char* name) {
    for (const auto& row : stats["cpu_scopes"])
        if (row["name"] == name) return &row;
    return nullptr;
}

// --instance-scaling: builtin:many at each instance count with --lod on (and --occlusion as
// given), forward and/or decoupled, in --rounds rounds; each round renders every count once, in
// an order rotated per round, so the machine's drift and the other processes on its cores hit
// every count alike. A count's figure is the median of its per-round medians (min and max of
// those are the spread); the ratio is cpu(N) / cpu(first N) within each round, then the median
// of those. cpu_frame_ms is the CPU time of renderFrame alone (GPU waits excluded): the scene's
// build, the bake and the upload happen before the first frame, outside it.
nlohmann::json runInstanceScalingBench(Gpu& gpu, const BenchOptions& b, RenderOptions o) {
    if (b.scene != "builtin:many")
        throw InputError(format("bench --instance-scaling: --scene %s: needs builtin:many (the "
                                "scene whose instance count --instances sets)",
                                b.scene.c_str()));
    if (b.scalingModes.empty())
        throw InputError("bench --instance-scaling: expected a --mode (forward, decoupled, both)");
    for (uint32_t n : b.instanceScaling)
        if (n == 0 || n > kManyMaxInstances)
            throw InputError(format("bench --instance-scaling: %u instances: expected 1..%u", n,
                                    kManyMaxInstances));
    const std::vector<uint32_t>& counts = b.instanceScaling;
    nlohmann::json out = roundsBenchHeader(gpu, b);
    out["lod"] = "on";
    out["occlusion"] = b.scalingOcclusion ? "on" : "off";
    out["cpu_scopes"] = b.cpuScopes;
    out["instance_counts"] = counts;
    o.lod = true;
    o.occlusion = b.scalingOcclusion;
    o.cpuScopes = b.cpuScopes;
    const char* coarseScope = "decoupled coarse allocation";
    const char* submitScope = "submit (all passes)"; // timed in every run
    struct PerRound {
        std::vector<double> cpu, thread, prepare, gpu, submits, coarse;
    };
    std::map<std::pair<RenderMode, uint32_t>, PerRound> rounds;
    uint32_t runs = b.rounds * uint32_t(b.scalingModes.size() * counts.size()), run = 0;
    for (uint32_t round = 0; round < b.rounds; ++round) {
        for (RenderMode mode : b.scalingModes) {
            for (size_t k = 0; k < counts.size(); ++k) {
                uint32_t n = counts[(k + round) % counts.size()];
                std::fprintf(stderr,
                             "bench: run %u/%u: round %u/%u, %s, %u instances, %u frames at "
                             "%ux%u\n",
                             ++run, runs, round + 1, b.rounds, modeName(mode), n, b.frames, b.width,
                             b.height);
                o.mode = mode;
                o.instances = n;
                RenderRun r = runRender(gpu, o);
                PerRound& pr = rounds[{mode, n}];
                pr.cpu.push_back(r.stats["cpu_frame_ms"]);
                pr.thread.push_back(r.stats["cpu_frame_thread_ms"]);
                pr.gpu.push_back(r.stats["frame_ms"]["median"]);
                std::vector<double> prepare;
                for (const FrameResult& f : r.frames) prepare.push_back(f.cpuPrepareMs);
                pr.prepare.push_back(median(prepare));
                const nlohmann::json* submits = cpuScopeRow(r.stats, submitScope);
                // The submits' own CPU time: the part of them cpu_frame_ms counts (a CPU
                // device's blocking inside a submit counts as waiting for the GPU: rhi/frame.cpp).
                pr.submits.push_back(submits ? (*submits)["thread_cpu_ms"].get<double>() : 0.0);
                if (const nlohmann::json* coarse = cpuScopeRow(r.stats, coarseScope))
                    pr.coarse.push_back((*coarse)["wall_ms"]);
                out["modes"][format("%s_%u", modeName(mode), n)] = std::move(r.stats);
            }
        }
    }
    auto minOf = [](const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); };
    auto maxOf = [](const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); };
    const nlohmann::json& firstStats =
        out["modes"][format("%s_%u", modeName(b.scalingModes[0]), counts[0])];
    std::printf("shadel bench --instance-scaling: %s at %ux%u on %s, %u frames x %u rounds, --lod "
                "on --occlusion %s; medians of the per-round medians [min..max] (timing: %s)\n",
                b.scene.c_str(), b.width, b.height, deviceLabel(gpu).c_str(), b.frames, b.rounds,
                b.scalingOcclusion ? "on" : "off", firstStats["timing"].get<std::string>().c_str());
    std::printf("  %-9s %9s %8s %24s %22s %10s %10s %10s %10s\n", "mode", "instances", "drawn",
                "cpu frame ms", "cpu ratio to first", "prepare", "coarse", "submits", "gpu frame");
    for (RenderMode mode : b.scalingModes) {
        const char* name = modeName(mode);
        const PerRound& first = rounds[{mode, counts[0]}];
        for (uint32_t n : counts) {
            const PerRound& pr = rounds[{mode, n}];
            const nlohmann::json& stats = out["modes"][format("%s_%u", name, n)];
            std::vector<double> ratios;
            for (size_t i = 0; i < pr.cpu.size(); ++i)
                ratios.push_back(first.cpu[i] > 0 ? pr.cpu[i] / first.cpu[i] : 0.0);
            nlohmann::json& row = out["instance_scaling"][name][std::to_string(n)];
            row = {{"instances", stats["instances"]},
                   {"instances_drawn", stats["instances_drawn"]},
                   {"triangles_drawn", stats["triangles_drawn"]},
                   {"cpu_frame_ms", median(pr.cpu)},
                   {"cpu_frame_ms_min", minOf(pr.cpu)},
                   {"cpu_frame_ms_max", maxOf(pr.cpu)},
                   {"cpu_frame_ms_per_round", pr.cpu},
                   {"cpu_frame_thread_ms", median(pr.thread)},
                   {"cpu_prepare_ms", median(pr.prepare)},
                   {"cpu_submits_ms", median(pr.submits)},
                   {"frame_ms", median(pr.gpu)},
                   {"frame_ms_per_round", pr.gpu},
                   {"cpu_ratio", median(ratios)},
                   {"cpu_ratio_min", minOf(ratios)},
                   {"cpu_ratio_max", maxOf(ratios)},
                   {"cpu_ratio_per_round", ratios}};
            if (!pr.coarse.empty()) row["cpu_coarse_allocation_ms"] = median(pr.coarse);
            if (n != counts[0])
                out["ratios"][format("instance_scaling_cpu_%s_%u", name, n)] = median(ratios);
            std::string coarse = pr.coarse.empty() ? "-" : format("%.3f", median(pr.coarse));
            std::printf("  %-9s %9u %8u %8.3f [%.3f..%.3f] %8.3f [%.2f..%.2f] %10.3f %10s %10.3f "
                        "%10.1f\n",
                        name, n, stats["instances_drawn"].get<uint32_t>(), median(pr.cpu),
                        minOf(pr.cpu), maxOf(pr.cpu), median(ratios), minOf(ratios), maxOf(ratios),
                        median(pr.prepare), coarse.c_str(), median(pr.submits), median(pr.gpu));
        }
        for (uint32_t n : counts) {
            if (n == counts[0]) continue;
            std::string perRound;
            for (const auto& r :
                 out["instance_scaling"][name][std::to_string(n)]["cpu_ratio_per_round"])
                perRound += format(" %.3f", r.get<double>());
            std::printf("  %s cpu(%u) / cpu(%u) per round:%s\n", name, n, counts[0],
                        perRound.c_str());
        }
    }
    std::printf("  (ms: cpu frame = renderFrame without GPU waits; prepare = its CPU frontend; "
                "coarse = the decoupled coarse allocation, with --cpu-scopes; submits = the "
                "vkQueueSubmit calls' thread CPU time; gpu frame = frame time)\n");
    if (!b.json.empty()) writeOutputFile(b.json, out.dump(2) + "\n");
    return out;
}

} // namespace

std::vector<uint32_t> parseInstanceCounts(const std::string& text) {
    if (text.empty())
        throw InputError(format("--instance-scaling '': expected instance counts N,N,... (each "
                                "1..%u)",
                                kManyMaxInstances));
    std::vector<uint32_t> counts;
    size_t start = 0;
    while (start <= text.size()) {
        size_t end = std::min(text.find(',', start), text.size());
        std::string item = text.substr(start, end - start);
        bool digits = !item.empty() && item.size() <= 7 &&
                      item.find_first_not_of("0123456789") == std::string::npos;
        uint32_t n = digits ? uint32_t(std::stoul(item)) : 0;
        if (n == 0 || n > kManyMaxInstances)
            throw InputError(format("--instance-scaling %s: '%s' is not an instance count 1..%u",
                                    text.c_str(), item.c_str(), kManyMaxInstances));
        if (std::find(counts.begin(), counts.end(), n) != counts.end())
            throw InputError(format("--instance-scaling %s: %u appears twice", text.c_str(), n));
        counts.push_back(n);
        start = end + 1;
    }
    return counts;
}

// Frames per turn of the side-by-side runs (renderSideBySide; 0: whole runs). Auto: half the
// frames, 1 to 4, so that even a short run (the spectra example's 3 frames) takes turns.
uint32_t benchFramesPerTurn(const BenchOptions& b) {
    if (b.framesPerTurn != BenchOptions::kFramesPerTurnAuto) return b.framesPerTurn;
    return std::clamp(b.frames / 2, 1u, 4u);
}

// The progress line's note on how the runs of a comparison share the device.
std::string interleaveNote(const BenchOptions& b) {
    uint32_t n = benchFramesPerTurn(b);
    return n ? format(" (turns of %u frame%s)", n, n == 1 ? "" : "s") : std::string();
}

// The stats of `runs`, rendered side by side. Interleaved (framesPerTurn > 0), every run is
// built first, then the runs take turns of framesPerTurn frames, the order rotating by one run
// each turn (A B C, B C A, C A B, ...): the host's drift (a shared machine's neighbours, its
// clocks) then reaches every run alike at the scale of a turn instead of favouring whichever ran
// in its quieter seconds. A turn's first frame finds the CPU's caches holding another run's data
// (on a CPU device that costs it): rotating, every turn of every run follows another run's (a
// reversed order would give the middle run twice the cold starts of the others), and a turn has
// a few frames so that the frame medians see warm ones. framesPerTurn 0 (--interleave runs): one
// whole run after another, in order. Runs may differ in frame count.
std::vector<nlohmann::json> renderSideBySide(Gpu& gpu, const std::vector<RenderOptions>& runs,
                                             uint32_t framesPerTurn, const std::string& label) {
    std::vector<nlohmann::json> stats(runs.size());
    if (framesPerTurn == 0) {
        for (size_t k = 0; k < runs.size(); ++k) stats[k] = runRender(gpu, runs[k]).stats;
        return stats;
    }
    std::vector<RenderSessionPtr> sessions;
    uint32_t frames = 0;
    for (const RenderOptions& o : runs) {
        try {
            sessions.push_back(beginRender(gpu, o));
        } catch (const DeviceError& e) {
            // Side by side, the runs hold the device's memory and bindless slots together: a
            // scene that fits once may not fit thrice. Then one run after another, said so.
            if (sessions.empty()) throw;
            SHADEL_WARN("%s: the runs do not fit on the device side by side (%s); rendering "
                        "them one after another (--interleave runs)",
                        label.c_str(), e.what());
            sessions.clear();
            return renderSideBySide(gpu, runs, 0, label);
        }
        frames = std::max(frames, o.frames);
    }
    const bool tty = isatty(STDERR_FILENO);
    auto allDone = [&] {
        return std::all_of(sessions.begin(), sessions.end(),
                           [](const RenderSessionPtr& s) { return renderSessionDone(*s); });
    };
    for (uint32_t turn = 0; !allDone(); ++turn) {
        for (size_t n = 0; n < sessions.size(); ++n) {
            RenderSession& session = *sessions[(n + turn) % sessions.size()];
            for (uint32_t f = 0; f < framesPerTurn && !renderSessionDone(session); ++f)
                renderNextFrame(session);
        }
        if (tty)
            std::fprintf(stderr, "\r%s: frame %u/%u", label.c_str(),
                         std::min((turn + 1) * framesPerTurn, frames), frames);
    }
    if (tty && frames) std::fprintf(stderr, "\n");
    for (size_t k = 0; k < sessions.size(); ++k) {
        stats[k] = finishRender(std::move(sessions[k])).stats;
        // The device's pools held every run of the comparison while this one ended.
        stats[k]["gpu_memory"]["runs_alive"] = sessions.size() - k;
    }
    return stats;
}

namespace {

// The three modes of the comparison.
struct BenchMode {
    const char* name;
    RenderMode mode;
    bool reuse;
};
const BenchMode kBenchModes[] = {{"forward", RenderMode::Forward, false},
                                 {"decoupled", RenderMode::Decoupled, false},
                                 {"reuse", RenderMode::Decoupled, true}};
const char* const kPathNames[] = {"static", "orbit", "walk"};

// What every run of the bench starts from.
RenderOptions benchBaseOptions(const BenchOptions& b) {
    RenderOptions o;
    static_cast<RenderSettings&>(o) = b; // the option table's settings, shared by every mode
    o.scene = b.scene;
    o.allowExternalFiles = b.allowExternalFiles;
    o.addDefaultSun = b.addDefaultSun;
    o.frames = b.frames;
    o.camera = b.camera;
    o.timing = b.timing;
    o.threads = b.threads;
    o.shadelsPerMetre = b.shadelsPerMetre;
    o.cameraPath = b.cameraPath;
    o.cacheLimitBytes = b.cacheLimitBytes;
    // --spectra compare reports on / off against the three modes: they run without spectra
    // (with auto, builtin:lights' decoupled mode would be on, and on / off compare on with on).
    if (b.compareSpectra) o.spectra = Spectra::Off;
    o.progress = false;
    o.instances = b.instances;
    return o;
}

// The forward / decoupled / reuse runs, --rounds rounds: out's modes, ratios, rounds.
void runModeRounds(Gpu& gpu, const BenchOptions& b, RenderOptions o, nlohmann::json& out) {
    // With --rounds N every round runs the three modes, in opposite order each round, so the
    // machine's drift over a run (a shared machine's neighbours, warm-up) hits every mode
    // alike; each ratio is the median of the rounds' ratios (forward of the same round as the
    // denominator), and modes.<name> keeps the last round's stats plus every round's median
    // frame (frame_ms_rounds).
    // --interleave (auto: half the frames, 1 to 4): within a round the three modes also take
    // turns of a few frames (renderSideBySide).
    const uint32_t modeCount = uint32_t(std::size(kBenchModes));
    std::vector<std::vector<double>> roundMs(modeCount);
    const uint32_t framesPerTurn = benchFramesPerTurn(b);
    out["interleave"] = framesPerTurn ? nlohmann::json(framesPerTurn) : nlohmann::json("runs");
    for (uint32_t round = 0; round < b.modeRounds; ++round) {
        std::vector<uint32_t> order;
        std::vector<RenderOptions> runs;
        std::string names;
        for (uint32_t k = 0; k < modeCount; ++k) {
            uint32_t index = round % 2 == 0 ? k : modeCount - 1 - k;
            order.push_back(index);
            o.mode = kBenchModes[index].mode;
            o.reuse = kBenchModes[index].reuse;
            runs.push_back(o);
            names += std::string(k ? ", " : "") + kBenchModes[index].name;
        }
        std::string label = "bench: " + names;
        std::fprintf(stderr, "%s%s, %u frames at %ux%u (%s camera)", label.c_str(),
                     interleaveNote(b).c_str(), b.frames, b.width, b.height,
                     kPathNames[int(b.cameraPath)]);
        if (b.modeRounds > 1) std::fprintf(stderr, ", round %u of %u", round + 1, b.modeRounds);
        std::fprintf(stderr, "\n");
        std::vector<nlohmann::json> stats = renderSideBySide(gpu, runs, framesPerTurn, label);
        for (uint32_t k = 0; k < modeCount; ++k) {
            const BenchMode& m = kBenchModes[order[k]];
            out["modes"][m.name] = std::move(stats[k]);
            roundMs[order[k]].push_back(out["modes"][m.name]["frame_ms"]["median"].get<double>());
        }
    }
    out["rounds"] = b.modeRounds;
    for (uint32_t k = 0; k < modeCount; ++k) {
        out["modes"][kBenchModes[k].name]["frame_ms_rounds"] = roundMs[k];
        out["modes"][kBenchModes[k].name]["frame_ms_median_of_rounds"] = median(roundMs[k]);
    }
    for (uint32_t k = 1; k < modeCount; ++k) {
        std::vector<double> ratios;
        for (uint32_t r = 0; r < b.modeRounds; ++r)
            ratios.push_back(roundMs[0][r] > 0 ? roundMs[k][r] / roundMs[0][r] : 0.0);
        out["ratios"][kBenchModes[k].name] = median(ratios);
        out["ratios_by_round"][kBenchModes[k].name] = ratios;
    }
}

// --light-culling compare: forward and decoupled (reuse off) again without light culling.
void compareLightCullingRuns(Gpu& gpu, RenderOptions o, nlohmann::json& out) {
    // The same forward and decoupled (reuse off) runs without light culling.
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        const char* name = mode == RenderMode::Forward ? "forward" : "decoupled";
        std::fprintf(stderr, "bench: %s, light culling none\n", name);
        o.mode = mode;
        o.reuse = false;
        o.lightCulling = LightCulling::None;
        nlohmann::json none = runRender(gpu, o).stats;
        double tiledMs = out["modes"][name]["frame_ms"]["median"];
        double noneMs = none["frame_ms"]["median"];
        out["modes"][std::string(name) + "_no_light_culling"] = none;
        out["ratios"][std::string("light_culling_") + name] = noneMs > 0 ? tiledMs / noneMs : 0.0;
    }
}

// --spectra compare: tile-shaded forward and decoupled by spectra and by one permutation.
void compareSpectraRuns(Gpu& gpu, const BenchOptions& b, RenderOptions o, nlohmann::json& out) {
    const uint32_t framesPerTurn = benchFramesPerTurn(b);
    // Tile-shaded forward and decoupled (reuse off), by spectra and by one all-features
    // permutation (the same classify + bin passes, one bin). On and single run in rounds
    // (--rounds, at least 2) of alternating order (on first, then single first): a single
    // pair on this shared machine swung on / single between 0.80 and 1.10. Each ratio is the
    // median of the rounds' ratios (each round's on over the same round's single), each
    // time the median of the rounds' medians; modes.<name> keeps the last run's stats.
    struct SpectraPath {
        const char* path;
        RenderMode mode;
        const char* onName;
        const char* singleName;
        const char* passNames;
        std::vector<const char*> passes;
    };
    const SpectraPath paths[] = {
        {"forward",
         RenderMode::Forward,
         "forward_spectra",
         "forward_spectra_single",
         "lightCulling + tileShading",
         {std::begin(kForwardSpectraPasses), std::end(kForwardSpectraPasses)}},
        {"decoupled",
         RenderMode::Decoupled,
         "decoupled_spectra",
         "decoupled_spectra_single",
         "shadelChunkSpectra + shadelShading",
         {std::begin(kDecoupledSpectraPasses), std::end(kDecoupledSpectraPasses)}}};
    auto ratio = [](double a, double b) { return b > 0 ? a / b : 0.0; };
    uint32_t spectraRounds = std::max(2u, b.modeRounds);
    for (const SpectraPath& path : paths) {
        std::vector<double> frameRounds[2], shadingRounds[2]; // [on, single] per round
        nlohmann::json runs = nlohmann::json::array();
        for (uint32_t round = 0; round < spectraRounds; ++round) {
            std::vector<RenderOptions> renders;
            for (int k = 0; k < 2; ++k) {
                bool on = (k == 0) == (round % 2 == 0); // on, single, then single, on
                o.mode = path.mode;
                o.reuse = false;
                o.lightCulling = b.lightCulling;
                o.spectra = on ? Spectra::On : Spectra::Single;
                renders.push_back(o);
            }
            std::string label = std::string("bench: ") + path.path + ", --spectra " +
                                (round % 2 == 0 ? "on, single" : "single, on");
            std::fprintf(stderr, "%s%s (round %u of %u)\n", label.c_str(),
                         interleaveNote(b).c_str(), round + 1, spectraRounds);
            std::vector<nlohmann::json> stats =
                renderSideBySide(gpu, renders, framesPerTurn, label);
            for (int k = 0; k < 2; ++k) {
                bool on = (k == 0) == (round % 2 == 0);
                nlohmann::json& st = stats[k];
                double frame = st["frame_ms"]["median"].get<double>();
                double shading = 0.0;
                for (const char* name : path.passes) shading += passMs(st, name);
                frameRounds[on ? 0 : 1].push_back(frame);
                shadingRounds[on ? 0 : 1].push_back(shading);
                runs.push_back({{"spectra", on ? "on" : "single"},
                                {"round", round + 1},
                                {"frame_ms", frame},
                                {"shading_ms", shading}});
                out["modes"][on ? path.onName : path.singleName] = std::move(st);
            }
        }
        o.spectra = Spectra::Off;
        bool forwardPath = path.mode == RenderMode::Forward;
        std::string key = std::string("spectra_") + path.path;
        std::vector<double> frameRatios, shadingRatios;
        for (uint32_t round = 0; round < spectraRounds; ++round) {
            frameRatios.push_back(ratio(frameRounds[0][round], frameRounds[1][round]));
            shadingRatios.push_back(ratio(shadingRounds[0][round], shadingRounds[1][round]));
        }
        double frameMs[2] = {median(frameRounds[0]), median(frameRounds[1])};
        double shadingMs[2] = {median(shadingRounds[0]), median(shadingRounds[1])};
        double frameRatio = median(frameRatios), shadingRatio = median(shadingRatios);
        out["ratios"][key] = frameRatio;
        out["ratios"][key + "_shading"] = shadingRatio;
        out["ratios_by_round"][key] = frameRatios;
        out["ratios_by_round"][key + "_shading"] = shadingRatios;
        out["spectra_frame_ms"][path.path] = {{"on", frameMs[0]}, {"single", frameMs[1]}};
        out["spectra_shading_ms"][path.path] = {{"on", shadingMs[0]}, {"single", shadingMs[1]}};
        out["spectra_runs"][path.path] = runs;
        // Against the path without spectra: the raster forward pass, the plain shadel shading.
        double other = out["modes"][path.path]["frame_ms"]["median"];
        const char* otherName = forwardPath ? "raster" : "off";
        out["ratios"][key + (forwardPath ? "_vs_raster" : "_vs_off")] = ratio(frameMs[0], other);
        std::printf("spectra (%s, %u rounds): on %.3f ms, single %.3f ms, %s %.3f ms; on / "
                    "single %.3f (median of the rounds'), on / %s %.3f\n",
                    path.path, spectraRounds, frameMs[0], frameMs[1], otherName, other, frameRatio,
                    otherName, ratio(frameMs[0], other));
        std::printf("spectra (%s) shading passes (%s): on %.3f ms, single %.3f ms; on / "
                    "single %.3f\n",
                    path.path, path.passNames, shadingMs[0], shadingMs[1], shadingRatio);
    }
}

// --threads compare: every mode serial and threaded.
void compareThreadRuns(Gpu& gpu, const BenchOptions& b, RenderOptions o, nlohmann::json& out) {
    // Render threading (rhi/frame.h): every mode serial (--threads 1) and threaded, in two
    // rounds of opposite order (serial first, then threaded first) so that warm-up and the
    // machine's drift hit both alike; each figure is the mean of its two runs' medians.
    // cpu_frame_ms is the wall clock of frontend + recording (GPU waits excluded): what
    // parallel recording shortens; cpu_frame_thread_ms the render thread's own CPU clock.
    uint32_t threaded = b.threads ? b.threads : defaultRecordingThreads();
    for (const BenchMode& m : kBenchModes) {
        o.mode = m.mode;
        o.reuse = m.reuse;
        double wall[2] = {0, 0}, thread[2] = {0, 0}, workers = 0, recording = 0;
        for (int round = 0; round < 2; ++round)
            for (int k = 0; k < 2; ++k) {
                bool serial = (k == 0) == (round == 0); // S,T then T,S
                std::fprintf(stderr, "bench: %s, --threads %u (round %d)\n", m.name,
                             serial ? 1u : threaded, round + 1);
                o.threads = serial ? 1 : threaded;
                nlohmann::json st = runRender(gpu, o).stats;
                wall[serial ? 0 : 1] += 0.5 * st["cpu_frame_ms"].get<double>();
                thread[serial ? 0 : 1] += 0.5 * st["cpu_frame_thread_ms"].get<double>();
                if (!serial) {
                    workers += 0.5 * st["recording"]["workers_cpu_ms"].get<double>();
                    recording += 0.5 * st["recording"]["wall_ms"].get<double>();
                }
            }
        out["threads"][m.name] = {{"threads", threaded},
                                  {"cpu_frame_ms_serial", wall[0]},
                                  {"cpu_frame_ms_threaded", wall[1]},
                                  {"cpu_frame_thread_ms_serial", thread[0]},
                                  {"cpu_frame_thread_ms_threaded", thread[1]},
                                  {"recording_wall_ms", recording},
                                  {"recording_workers_cpu_ms", workers}};
        out["ratios"][std::string("threads_cpu_") + m.name] = wall[0] > 0 ? wall[1] / wall[0] : 0.0;
        std::printf("threads (%s): cpu frame %.3f ms with %u threads, %.3f ms serial = %.3f "
                    "(render thread's CPU clock %.3f / %.3f ms); recording %.3f ms wall, "
                    "%.3f ms CPU on the workers\n",
                    m.name, wall[1], threaded, wall[0], wall[0] > 0 ? wall[1] / wall[0] : 0.0,
                    thread[1], thread[0], recording, workers);
    }
}

// The comparison as a table on stdout.
void printBenchTable(const Gpu& gpu, const BenchOptions& b, const nlohmann::json& out) {
    const nlohmann::json& forward = out["modes"]["forward"];
    std::printf("shadel bench: %s at %ux%u on %s, %u frames, %s camera, medians (timing: %s)%s\n",
                b.scene.c_str(), b.width, b.height, deviceLabel(gpu).c_str(), b.frames,
                kPathNames[int(b.cameraPath)], forward["timing"].get<std::string>().c_str(),
                b.modeRounds > 1 ? format(", %u rounds", b.modeRounds).c_str() : "");
    std::printf("%-28s %12s %12s %12s\n", "", "forward", "decoupled", "reuse");
    auto row = [&](const char* label, auto value) {
        std::printf("%-28s", label);
        for (const BenchMode& m : kBenchModes)
            std::printf(" %12s", value(out["modes"][m.name]).c_str());
        std::printf("\n");
    };
    // With rounds: the median over the rounds of each round's median frame, and the median
    // of the rounds' ratios (what --json's ratios hold); the passes below are the last round's.
    row("frame ms", [](const nlohmann::json& s) {
        return format("%.3f", s["frame_ms_median_of_rounds"].get<double>());
    });
    std::printf("%-28s", "ratio to forward");
    for (const BenchMode& m : kBenchModes) std::printf(" %12.3f", out["ratios"].value(m.name, 1.0));
    std::printf("\n");
    row("cpu frame ms",
        [](const nlohmann::json& s) { return format("%.3f", s["cpu_frame_ms"].get<double>()); });
    row("recording threads", [](const nlohmann::json& s) {
        return format("%u", s["recording"]["threads"].get<uint32_t>());
    });
    // Passes: union by name, in frame order.
    std::vector<std::string> names;
    for (const BenchMode& m : kBenchModes)
        for (const auto& p : out["modes"][m.name]["passes"])
            if (std::find(names.begin(), names.end(), p["name"]) == names.end())
                names.push_back(p["name"]);
    // A pass that ran on fewer frames than the run's (the kept shadow maps: drawn when they
    // change) shows its median over those frames and, in brackets, how many they were.
    bool partial = false;
    for (const std::string& n : names)
        row(("  " + n).c_str(), [&](const nlohmann::json& s) {
            for (const auto& p : s["passes"]) {
                if (p["name"] != n) continue;
                uint32_t ran = p.value("frames", 0u), frames = s.value("frames", 0u);
                if (ran >= frames) return format("%.3f", p["gpu_ms"].get<double>());
                partial = true;
                return format("%.3f [%u]", p["gpu_ms"].get<double>(), ran);
            }
            return std::string("-");
        });
    if (partial)
        std::printf("%-28s [N]: ran on N of the %u frames (its median over those)\n", "", b.frames);
    auto decoupledOnly = [](const char* key, const char* fmt) {
        return [key, fmt](const nlohmann::json& s) {
            if (!s.contains(key)) return std::string("-");
            return s[key].is_number_float()
                       ? format(fmt, s[key].get<double>())
                       : format("%llu", (unsigned long long)s[key].get<uint64_t>());
        };
    };
    row("shadels per covered pixel", decoupledOnly("shadels_per_pixel", "%.3f"));
    // Material shading rate (render/shadel/material_rate.h): objects shaded coarser, mean MIPs.
    row("objects rate-biased", decoupledOnly("objects_rate_biased", ""));
    row("material rate bias (mean)", decoupledOnly("material_rate_bias_mean", "%.3f"));
    row("shadels shaded (last)", decoupledOnly("shadels_shaded", ""));
    row("reuse fraction", decoupledOnly("reuse_fraction", "%.3f"));
    // Why the chunks not carried over were shaded (fractions of the stored chunks).
    for (const char* reason :
         {"new", "refresh", "view", "not_reusable", "near_change", "rt_history"})
        row(("  shaded: " + std::string(reason)).c_str(), [reason](const nlohmann::json& s) {
            if (!s.contains("shaded_because")) return std::string("-");
            return format("%.3f", s["shaded_because"][reason].get<double>());
        });
    row("occupancy bits per shadel", decoupledOnly("occupancy_bits_per_shadel", "%.3f"));
    row("reconstruction misses", decoupledOnly("reconstruction_misses", ""));
    if (b.compareLightCulling)
        for (const char* name : {"forward", "decoupled"})
            std::printf("light culling, %s: tiled %.3f ms / none %.3f ms = %.3f\n", name,
                        out["modes"][name]["frame_ms"]["median"].get<double>(),
                        out["modes"][std::string(name) + "_no_light_culling"]["frame_ms"]["median"]
                            .get<double>(),
                        out["ratios"][std::string("light_culling_") + name].get<double>());
}

} // namespace

// Renders the same scene over the same camera path forward, decoupled with reuse off and
// decoupled with reuse on, in one process, and prints per-pass medians and frame-time ratios
// against forward (the stats contract in docs/design.md, §7).
nlohmann::json runBench(Gpu& gpu, const BenchOptions& b) {
    if (!b.json.empty()) requireCreatableOutput("--json", b.json); // before minutes of rendering
    if (!b.plot.empty()) requireCreatableOutput("--plot", b.plot);
    requireDistinctOutputs({{"--json", b.json}, {"--plot", b.plot}});
    validate(b);
    const RenderOptions o = benchBaseOptions(b);
    if (b.compareShadowCulling) return runShadowCullingBench(gpu, b, o);
    if (b.compareEnvironment) return runEnvironmentBench(gpu, b, o);
    if (b.compareParticleLighting) return runParticleLightingBench(gpu, b, o);
    if (b.compareStencil) return runStencilBench(gpu, b, o);
    if (b.compareStreaming) return runStreamingBench(gpu, b, o);
    if (!b.instanceScaling.empty()) return runInstanceScalingBench(gpu, b, o);
    nlohmann::json out;
    out["scene"] = b.scene;
    recordDevice(out, gpu);
    out["frames"] = b.frames;
    out["camera_path"] = kPathNames[int(b.cameraPath)];
    out["settings"] = settingsJson({b, b.addDefaultSun}, kBenchCommand);
    runModeRounds(gpu, b, o, out);
    if (b.compareLightCulling) compareLightCullingRuns(gpu, o, out);
    if (b.compareSpectra) compareSpectraRuns(gpu, b, o, out);
    if (b.compareThreads) compareThreadRuns(gpu, b, o, out);
    printBenchTable(gpu, b, out);
    if (!b.plot.empty()) writeBenchPlot(out, b.plot);
    if (!b.json.empty()) writeOutputFile(b.json, out.dump(2) + "\n");
    return out;
}

} // namespace shadel
