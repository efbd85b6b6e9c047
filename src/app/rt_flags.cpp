#include "app/rt_flags.h"

#include <cmath>

#include "app/commands.h"
#include "core/error.h"
#include "core/log.h"

namespace shadel {

void addRayTracingFlags(CLI::App& render, RtFlags& f) {
    RtSettings& s = f.settings;
    render
        .add_option(
            "--rt-shadows", f.shadows,
            "on | off: ray-traced sun and shadow-casting spot shadows (in place of the maps)")
        ->capture_default_str();
    render.add_option("--rt-ao", f.ao, "on | off: ray-traced ambient occlusion")
        ->capture_default_str();
    render.add_option("--rt-gi", f.gi, "on | off: one bounce of ray-traced diffuse light")
        ->capture_default_str();
    render
        .add_option("--rt-shadow-rays", s.shadowRays,
                    "sun rays per sample, 1..64 (1: hard shadows; more: soft, jittered over "
                    "the sun's disc)")
        ->capture_default_str();
    render
        .add_option("--rt-sun-angle", s.sunAngleDegrees,
                    "half angle of the sun's disc in degrees, 0..10 (soft shadows)")
        ->capture_default_str();
    render.add_option("--rt-ao-rays", s.aoRays, "forward: AO rays per pixel, 1..256")
        ->capture_default_str();
    render.add_option("--rt-ao-radius", s.aoRadius, "AO ray length (scene units, > 0)")
        ->capture_default_str();
    render.add_option("--rt-gi-rays", s.giRays, "forward: GI rays per pixel, 1..256")
        ->capture_default_str();
    render
        .add_option("--rt-filter", f.filter,
                    "on | off: forward: 3x3 depth-aware filter of the traced AO, GI and soft "
                    "shadows")
        ->capture_default_str();
    render
        .add_option("--rays-per-shadel", s.raysPerShadel,
                    "decoupled: AO / GI rays per shadel per frame, 1..256")
        ->capture_default_str();
    render
        .add_option("--rt-shadel-mip-offset", s.shadelMipOffset,
                    "decoupled: the RT cache's MIP, this many levels coarser than the finest "
                    "the view needs, 0..8")
        ->capture_default_str();
    render
        .add_option("--rt-distance", s.distance,
                    "TLAS: instances within this distance of the camera (0 = all)")
        ->capture_default_str();
    render
        .add_option("--rt-history-rays", s.historyRays,
                    "decoupled: rays a cached texel accumulates, then reuses until its inputs "
                    "change, 1..1024")
        ->capture_default_str();
    render
        .add_option("--rt-animated-blas", f.animatedBlas,
                    "on | off: GPU-skinned meshes' BLASes refit as the pose changes (rebuilt "
                    "every 8 refits; beyond 16 m at most every ceil(distance / 16 m) frames); "
                    "off: the bind pose's")
        ->capture_default_str();
    render.add_option("--blas-pool-mb", s.blasPoolMb, "BLAS memory pool size in MiB, 1..4096")
        ->capture_default_str();
    render
        .add_option("--blas-pool-limit", s.blasPoolLimit,
                    "most BLAS pools, 1..1024 (beyond: BLASes fall back to the least-detailed "
                    "LOD's)")
        ->capture_default_str();
}

RtSettings parseRayTracingFlags(const RtFlags& f) {
    RtSettings s = f.settings;
    s.shadows = parseOnOff("--rt-shadows", f.shadows);
    s.ao = parseOnOff("--rt-ao", f.ao);
    s.gi = parseOnOff("--rt-gi", f.gi);
    s.spatialFilter = parseOnOff("--rt-filter", f.filter);
    s.animatedBlas = parseOnOff("--rt-animated-blas", f.animatedBlas);
    auto count = [](const char* flag, uint32_t v, uint32_t lo, uint32_t hi) {
        if (v < lo || v > hi) throw InputError(format("%s %u: expected %u..%u", flag, v, lo, hi));
    };
    auto real = [](const char* flag, float v, float lo, float hi) {
        if (!std::isfinite(v) || v < lo || v > hi)
            throw InputError(
                format("%s %g: expected %g..%g", flag, double(v), double(lo), double(hi)));
    };
    count("--rt-shadow-rays", s.shadowRays, 1, 64);
    count("--rt-ao-rays", s.aoRays, 1, 256);
    count("--rt-gi-rays", s.giRays, 1, 256);
    count("--rays-per-shadel", s.raysPerShadel, 1, 256);
    count("--rt-shadel-mip-offset", s.shadelMipOffset, 0, 8);
    count("--rt-history-rays", s.historyRays, 1, 1024); // rgba16f counts exactly to 2048
    count("--blas-pool-mb", s.blasPoolMb, 1, 4096);
    count("--blas-pool-limit", s.blasPoolLimit, 1, 1024);
    real("--rt-sun-angle", s.sunAngleDegrees, 0.0f, 10.0f);
    real("--rt-ao-radius", s.aoRadius, 1e-4f, 1e6f);
    real("--rt-distance", s.distance, 0.0f, 1e9f);
    return s;
}

} // namespace shadel
