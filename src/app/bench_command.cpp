#include <cstdio>
#include <fstream>

#include "app/commands.h"
#include "app/output_files.h"
#include "core/error.h"
#include "core/log.h"

namespace shadel {

// Renders the same scene in both modes in one process and prints decoupled / forward ratios.
nlohmann::json runBench(Gpu& gpu, const BenchOptions& b) {
    if (!b.json.empty()) requireCreatableOutput("--json", b.json); // before minutes of rendering
    RenderOptions o;
    o.scene = b.scene;
    o.allowExternalFiles = b.allowExternalFiles;
    o.width = b.width;
    o.height = b.height;
    o.frames = b.frames;
    o.camera = b.camera;
    o.timing = b.timing;
    o.shadelsPerMetre = b.shadelsPerMetre;
    o.cacheDir = b.cacheDir;
    o.cacheLimitBytes = b.cacheLimitBytes;
    o.progress = false;

    std::fprintf(stderr, "bench: forward, %u frames at %ux%u\n", b.frames, b.width, b.height);
    o.mode = RenderMode::Forward;
    nlohmann::json forward = runRender(gpu, o).stats;
    std::fprintf(stderr, "bench: decoupled, %u frames at %ux%u\n", b.frames, b.width, b.height);
    o.mode = RenderMode::Decoupled;
    nlohmann::json decoupled = runRender(gpu, o).stats;

    nlohmann::json out;
    out["scene"] = b.scene;
    out["device"] = gpu.device.name;
    out["forward"] = forward;
    out["decoupled"] = decoupled;
    double fwd = forward["frame_ms"]["median"], dec = decoupled["frame_ms"]["median"];
    out["frame_ratio"] = fwd > 0 ? dec / fwd : 0.0;

    std::printf("shadel bench: %s at %ux%u on %s, %u frames, medians (timing: %s)\n",
                b.scene.c_str(), b.width, b.height, gpu.device.name.c_str(), b.frames,
                forward["timing"].get<std::string>().c_str());
    std::printf("%-26s %12s %12s %8s\n", "", "forward ms", "decoupled ms", "ratio");
    std::printf("%-26s %12.3f %12.3f %8.3f\n", "frame", fwd, dec, fwd > 0 ? dec / fwd : 0.0);
    // Passes: union by name, in frame order of the decoupled path.
    auto find = [](const nlohmann::json& passes, const std::string& name) -> double {
        for (const auto& p : passes)
            if (p["name"] == name) return p["gpu_ms"];
        return -1.0;
    };
    std::vector<std::string> names;
    for (const auto& p : forward["passes"]) names.push_back(p["name"]);
    for (const auto& p : decoupled["passes"])
        if (std::find(names.begin(), names.end(), p["name"]) == names.end())
            names.push_back(p["name"]);
    for (const std::string& n : names) {
        double f = find(forward["passes"], n), d = find(decoupled["passes"], n);
        std::printf("  %-24s %12s %12s\n", n.c_str(), f >= 0 ? format("%.3f", f).c_str() : "-",
                    d >= 0 ? format("%.3f", d).c_str() : "-");
    }
    std::printf("%-26s %12s %12.3f\n", "shadels per covered pixel", "-",
                decoupled["shadels_per_pixel"].get<double>());
    if (decoupled.contains("occupancy_bits_per_shadel"))
        std::printf("%-26s %12s %12.3f\n", "occupancy bits per shadel", "-",
                    decoupled["occupancy_bits_per_shadel"].get<double>());
    std::printf("%-26s %12s %12s\n", "storage used (chunks)", "-",
                format("%llu/%llu",
                       (unsigned long long)decoupled["chunks_allocated"].get<uint64_t>(),
                       (unsigned long long)decoupled["chunks_capacity"].get<uint64_t>())
                    .c_str());
    std::printf("%-26s %12llu %12llu\n", "reconstruction misses", 0ull,
                (unsigned long long)decoupled["reconstruction_misses"].get<uint64_t>());
    if (!b.json.empty()) writeOutputFile(b.json, out.dump(2) + "\n");
    return out;
}

} // namespace shadel
