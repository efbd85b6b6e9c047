#include "app/cli_validate.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <tuple>

#include "app/commands.h"
#include "bake/cache_eviction.h"
#include "core/error.h"
#include "core/log.h"

namespace shadel {
namespace {

// "" or why `value` is not a finite number in range.
std::string rangeProblem(double value, FloatRange r) {
    if (!std::isfinite(value)) return "must be a finite number";
    bool aboveMin = r.minExclusive ? value > r.min : value >= r.min;
    if (!aboveMin || value > r.max)
        return format("must be in %s%g, %g]", r.minExclusive ? "(" : "[", r.min, r.max);
    return {};
}

std::string oneLine(std::string text) {
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    for (size_t at; (at = text.find('\n')) != std::string::npos;) text.replace(at, 1, "; ");
    return text;
}

// "" and the three values, or why `text` is not "X,Y,Z" of finite numbers in range.
std::string vec3Problem(const std::string& text, FloatRange r, glm::vec3& out) {
    const char* p = text.c_str();
    for (int i = 0; i < 3; ++i) {
        char* end = nullptr;
        double value = std::strtod(p, &end);
        if (end == p) return "expected X,Y,Z (three numbers separated by commas)";
        if (std::string problem = rangeProblem(value, r); !problem.empty())
            return format("%c %s", "XYZ"[i], problem.c_str());
        out[i] = float(value);
        p = end;
        if (i < 2) {
            if (*p != ',') return "expected X,Y,Z (three numbers separated by commas)";
            ++p;
        }
    }
    return *p == '\0' ? std::string() : "expected X,Y,Z (three numbers separated by commas)";
}

} // namespace

CLI::Validator finiteVec3(FloatRange range) {
    auto check = [=](std::string& text) -> std::string {
        glm::vec3 v;
        std::string problem = vec3Problem(text, range, v);
        return problem.empty() ? problem : text + ": " + problem;
    };
    return CLI::Validator(check, "X,Y,Z");
}

glm::vec3 parseVec3(const char* flag, const std::string& text, FloatRange range) {
    glm::vec3 v(0.0f);
    if (std::string problem = vec3Problem(text, range, v); !problem.empty())
        throw InputError(format("%s %s: %s", flag, text.c_str(), problem.c_str()));
    return v;
}

CLI::Validator finiteInRange(FloatRange range) {
    auto check = [=](std::string& text) -> std::string {
        char* end = nullptr;
        double value = std::strtod(text.c_str(), &end);
        if (text.empty() || end != text.c_str() + text.size()) return text + ": not a number";
        std::string problem = rangeProblem(value, range);
        return problem.empty() ? problem : text + ": " + problem;
    };
    return CLI::Validator(
        check, format("FINITE %s%g..%g]", range.minExclusive ? "(" : "[", range.min, range.max));
}

CLI::Validator byteSize() {
    auto check = [](std::string& text) -> std::string {
        uint64_t bytes = 0;
        return parseByteSize(text, bytes) ? std::string()
                                          : text + ": expected a size such as 4G, 512M or 0";
    };
    return CLI::Validator(check, "SIZE");
}

std::string checkFiniteInRange(const char* flag, double value, FloatRange range) {
    std::string problem = rangeProblem(value, range);
    return problem.empty() ? problem : format("%s %g: %s", flag, value, problem.c_str());
}

void validateRenderOptions(const RenderOptions& o) {
    const std::tuple<const char*, double, FloatRange> floats[] = {
        {"--exposure", o.exposure, kExposureRange},
        {"--density", o.shadelsPerMetre, kDensityRange},
        {"--shading-bias", o.shadingBias, kShadingBiasRange},
        {"--trilinear-band", o.trilinearBand, kTrilinearBandRange},
        {"--shadel-budget", o.shadelBudget, kShadelBudgetRange},
        {"--forward-below", o.forwardBelowPixels, kForwardBelowRange},
        {"--df-shadow-start", o.dfShadowStart, kDfDistanceRange},
        {"--df-residency", o.dfResidency, kDfDistanceRange},
    };
    for (const auto& [flag, value, range] : floats)
        if (std::string problem = checkFiniteInRange(flag, value, range); !problem.empty())
            throw InputError(problem);
    if (o.textureBudgetMiB != 0.0) // 0: no budget
        if (std::string problem =
                checkFiniteInRange("--texture-budget", o.textureBudgetMiB, kTextureBudgetRange);
            !problem.empty())
            throw InputError(problem);
    if (o.time)
        if (std::string problem = checkFiniteInRange("--time", *o.time, kTimeRange);
            !problem.empty())
            throw InputError(problem);
    if (o.timeStep) {
        if (std::string problem = checkFiniteInRange("--time-step", *o.timeStep, kTimeStepRange);
            !problem.empty())
            throw InputError(problem);
        if (o.scene.rfind("builtin:", 0) == 0)
            throw InputError(format("--time-step %g: plays glTF animations; %s has none",
                                    *o.timeStep, o.scene.c_str()));
    }
    const CameraOverrides& c = o.cameraOverrides;
    if (c.fovDegrees != 0.0f)
        if (std::string problem = checkFiniteInRange("--fov", c.fovDegrees, kFovRange);
            !problem.empty())
            throw InputError(problem);
    for (const auto& [flag, v] : {std::pair{"--from", c.from}, std::pair{"--look-at", c.lookAt}})
        for (int i = 0; v && i < 3; ++i)
            if (std::string problem = checkFiniteInRange(flag, (*v)[i], kCoordinateRange);
                !problem.empty())
                throw InputError(problem);
    // Counts, and options that need another (checked here, before the scene is loaded and
    // baked, not where the renderer is built).
    auto requireCount = [](const char* flag, uint32_t value, uint32_t lo, uint32_t hi) {
        if (value < lo || value > hi)
            throw InputError(format("%s %u: expected %u..%u", flag, value, lo, hi));
    };
    requireCount("--material-samples", o.materialSamples, 1, 64);
    requireCount("--allocation-counters", o.allocationCounters, 1, SHADEL_COUNTERS);
    requireCount("--reuse-refresh", o.reuseRefreshPeriod, 1, 1024);
    requireCount("--particle-atlas-size", o.particleAtlasSize, 128, 8192);
    requireCount("--gi-iterations", o.giIterations, 0, 64);
    if (o.visualize == Visualize::Gi && o.gi == GiMode::Off)
        throw InputError("--visualize gi: shows the indirect light of --gi lpv; GI is off");
    if (o.visualize == Visualize::RtAo && !o.rt.ao)
        throw InputError("--visualize rt-ao: shows the ray-traced AO of --rt-ao on; it is off");
    if (o.visualize == Visualize::Reuse && o.mode != RenderMode::Decoupled)
        throw InputError("--visualize reuse: shows which shadel chunks were carried over; add "
                         "--mode decoupled");
    if (o.visualize == Visualize::Tiles && !o.screenSpace)
        throw InputError(
            "--visualize tiles: shows the tile classes of --screen-space on; it is off");
    if (o.distanceFields && !o.screenSpace)
        throw InputError(
            "--distance-fields on: runs on the screen-space tiles; add --screen-space on");
    if (o.stencilEffects != StencilEffects::Off && !o.screenSpace)
        throw InputError("--stencil-effects: composites the screen-space reflections; add "
                         "--screen-space on");
}

int exitForParseError(const CLI::App& app, const CLI::ParseError& error) {
    // --help, --help-all and --version are "errors" with exit code 0 that print their text.
    if (error.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(error);
    std::fprintf(stderr, "shadel: %s (see --help)\n", oneLine(error.what()).c_str());
    return kExitBadInput;
}

} // namespace shadel
