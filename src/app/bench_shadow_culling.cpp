#include <cstdio>
#include <utility>
#include <vector>

#include "app/commands.h"
#include "app/output_files.h"
#include "app/stats_schema.h"

namespace shadel {

// --shadow-culling-compare: the same forward frames with every sun cascade and shadow-casting
// spot drawing its own GPU-culled casters (per-view) and the sun's whole-scene list
// (whole-scene). The shadow passes are the sun's map, the cascades and the spot maps (drawn
// when the spots changed, or the camera while it chooses their casters: whole-scene or --lod
// on; with a static camera, the first frame only). Each pass's median is over the frames that
// ran it; "shadow passes" is the median over frames of each frame's shadow passes.
// instanceCull is reported apart, since per-view culling moves work into it.
nlohmann::json runShadowCullingBench(Gpu& gpu, const BenchOptions& b, RenderOptions o) {
    nlohmann::json out;
    out["scene"] = b.scene;
    recordDevice(out, gpu);
    out["frames"] = b.frames;
    out["sun_cascades"] = b.sunCascades;
    o.mode = RenderMode::Forward;
    // The sun's map drawn every frame, in both: a kept map (--shadow-cache on) is drawn once,
    // and per-view culling keeps it only because whole-scene culling cannot.
    o.sunShadowCache = false;
    const char* shadowPasses[] = {"shadowMap", "sunCascades", "spotShadowMaps"};
    // A discarded one-frame run first: the first frame of a process pays for first-touch memory
    // (the 4096^2 spot atlas) and pipeline creation, which would land on the first mode alone.
    {
        RenderOptions warm = o;
        warm.frames = 1;
        std::fprintf(stderr, "bench: warm-up frame\n");
        runRender(gpu, warm);
    }
    for (auto [name, culling] : {std::pair{"per_view", ShadowCulling::PerView},
                                 std::pair{"whole_scene", ShadowCulling::WholeScene}}) {
        std::fprintf(stderr, "bench: shadow culling %s, %u frames at %ux%u\n", name, b.frames,
                     b.width, b.height);
        o.shadowCulling = culling;
        RenderRun run = runRender(gpu, o);
        // Each pass's median over the frames that ran it (the stats), and the median of each
        // frame's shadow passes together (frames without a spot-map redraw count less).
        std::vector<double> perFrame;
        for (const FrameResult& f : run.frames) {
            double ms = 0.0;
            for (const PassTiming& t : f.passes)
                for (const char* p : shadowPasses) ms += t.name == p ? t.gpuMs : 0.0;
            perFrame.push_back(ms);
        }
        for (const char* p : shadowPasses) out["shadow_ms"][name][p] = passMs(run.stats, p);
        out["shadow_ms"][name]["total"] = median(perFrame);
        out["shadow_ms"][name]["instanceCull"] = passMs(run.stats, "instanceCull");
        nlohmann::json stats = std::move(run.stats);
        out["modes"][name] = std::move(stats);
    }
    auto ratio = [](double a, double b) { return b > 0 ? a / b : 0.0; };
    const nlohmann::json& pv = out["modes"]["per_view"];
    const nlohmann::json& ws = out["modes"]["whole_scene"];
    double framePv = pv["frame_ms"]["median"], frameWs = ws["frame_ms"]["median"];
    double shadowPv = out["shadow_ms"]["per_view"]["total"];
    double shadowWs = out["shadow_ms"]["whole_scene"]["total"];
    double cullPv = out["shadow_ms"]["per_view"]["instanceCull"];
    double cullWs = out["shadow_ms"]["whole_scene"]["instanceCull"];
    out["ratios"]["shadow_culling_frame"] = ratio(framePv, frameWs);
    out["ratios"]["shadow_culling_shadow_passes"] = ratio(shadowPv, shadowWs);
    out["ratios"]["shadow_culling_instance_cull"] = ratio(cullPv, cullWs);
    std::printf("shadel bench --shadow-culling-compare: %s at %ux%u on %s, %u frames, "
                "--sun-cascades %u, medians (timing: %s)\n",
                b.scene.c_str(), b.width, b.height, deviceLabel(gpu).c_str(), b.frames,
                b.sunCascades, pv["timing"].get<std::string>().c_str());
    std::printf("  %-16s %12s %12s %8s\n", "", "per-view", "whole-scene", "ratio");
    std::printf("  %-16s %9.3f ms %9.3f ms %8.3f\n", "frame", framePv, frameWs,
                ratio(framePv, frameWs));
    for (const char* p : shadowPasses) {
        double a = out["shadow_ms"]["per_view"][p], c = out["shadow_ms"]["whole_scene"][p];
        std::printf("  %-16s %9.3f ms %9.3f ms %8.3f\n", p, a, c, ratio(a, c));
    }
    std::printf("  %-16s %9.3f ms %9.3f ms %8.3f\n", "shadow passes", shadowPv, shadowWs,
                ratio(shadowPv, shadowWs));
    std::printf("  %-16s %9.3f ms %9.3f ms %8.3f\n", "instanceCull", cullPv, cullWs,
                ratio(cullPv, cullWs));
    // Casters drawn per shadow view (the last frame's counts).
    for (const auto& [view, row] : pv["culling"]["views"].items()) {
        if (view == "camera") continue;
        std::printf("  drawn %-14s %9u    %9u\n", view.c_str(),
                    row["instances_drawn"].get<uint32_t>(),
                    ws["culling"]["views"][view]["instances_drawn"].get<uint32_t>());
    }
    writeBenchJson(b.json, out);
    return out;
}

} // namespace shadel
