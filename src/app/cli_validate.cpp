#include "app/cli_validate.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <tuple>

#include "app/commands.h"
#include "app/option_table.h"
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

namespace {

void throwIf(const std::string& problem) {
    if (!problem.empty()) throw InputError(problem);
}

void requireCount(const char* flag, uint32_t value, uint32_t lo, uint32_t hi) {
    if (value < lo || value > hi)
        throw InputError(format("%s %u: expected %u..%u", flag, value, lo, hi));
}

// The command's own floats (the table checks the settings').
void validateCommandFloats(const RenderOptions& o) {
    throwIf(checkFiniteInRange("--density", o.shadelsPerMetre, kDensityRange));
    throwIf(checkFiniteInRange("--shadel-budget", o.shadelBudget, kShadelBudgetRange));
    if (o.textureBudgetMiB != 0.0) // 0: no budget
        throwIf(checkFiniteInRange("--texture-budget", o.textureBudgetMiB, kTextureBudgetRange));
    if (o.time) throwIf(checkFiniteInRange("--time", *o.time, kTimeRange));
    if (o.timeStep) throwIf(checkFiniteInRange("--time-step", *o.timeStep, kTimeStepRange));
    const CameraOverrides& c = o.cameraOverrides;
    if (c.fovDegrees != 0.0f) throwIf(checkFiniteInRange("--fov", c.fovDegrees, kFovRange));
    for (const auto& [flag, v] : {std::pair{"--from", c.from}, std::pair{"--look-at", c.lookAt}})
        for (int i = 0; v && i < 3; ++i)
            throwIf(checkFiniteInRange(flag, (*v)[i], kCoordinateRange));
}

// Options that need another, or a value inside the image.
void validateCombinations(const RenderOptions& o) {
    if (o.timeStep && o.scene.rfind("builtin:", 0) == 0)
        throw InputError(format("--time-step %g: plays glTF animations; %s has none", *o.timeStep,
                                o.scene.c_str()));
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
    if (o.distanceFieldLighting && !o.screenSpace)
        throw InputError(
            "--distance-fields on: runs on the screen-space tiles; add --screen-space on");
    if (o.stencilEffects != StencilEffects::Off && !o.screenSpace)
        throw InputError("--stencil-effects: composites the screen-space reflections; add "
                         "--screen-space on");
    bool listCaptures = o.captures.size() == 1 && o.captures[0] == "list";
    if (!o.captures.empty() && !listCaptures && o.captureDir.empty() && o.out.empty())
        throw InputError("--capture: needs --capture-dir DIR or --out (files go next to it)");
    if (o.inspectX >= int32_t(o.width) || o.inspectY >= int32_t(o.height))
        throw InputError(format("--inspect %d,%d: outside the %ux%u image", o.inspectX, o.inspectY,
                                o.width, o.height));
    if (o.debugLinesAtX >= 0 && (o.debugLines & (DEBUG_LINES_LIGHTS | DEBUG_LINES_BLOCKERS)) == 0)
        throw InputError(format("--debug-lines-at %d,%d: picks lights, so it needs --debug-lines "
                                "lights or blockers",
                                o.debugLinesAtX, o.debugLinesAtY));
    if (o.debugLinesAtX >= int32_t(o.width) || o.debugLinesAtY >= int32_t(o.height))
        throw InputError(format("--debug-lines-at %d,%d: outside the %ux%u image", o.debugLinesAtX,
                                o.debugLinesAtY, o.width, o.height));
    if (o.aaFrames > 1 &&
        (o.aa != AntiAliasing::Taa || o.frames != 1 || o.cameraPath != CameraPath::Static))
        throw InputError(format("--aa-frames %u: accumulates a still; needs --aa taa, --frames 1 "
                                "and --camera-path static",
                                o.aaFrames));
    if (o.aa == AntiAliasing::Taa && o.mode == RenderMode::Reference)
        throw InputError("--aa taa with --mode reference: the path tracer jitters its own "
                         "samples inside each pixel and averages them; it needs no TAA");
    if (o.aa == AntiAliasing::Taa && o.ssaa != 1)
        throw InputError(format("--aa taa with --ssaa %u: TAA resolves one sample per pixel; use "
                                "one of them",
                                o.ssaa));
}

} // namespace

void validate(const RenderOptions& o) {
    requireCount("--frames", o.frames, 1, 100000);
    throwIf(checkSettings({o, o.addDefaultSun}, kRenderCommand));
    validateCommandFloats(o);
    if (o.instances != 0) requireCount("--instances", o.instances, 1, 1000000);
    validateCombinations(o);
}

void validate(const BenchOptions& b) {
    throwIf(checkSettings({b, b.addDefaultSun}, kBenchCommand));
    throwIf(checkFiniteInRange("--density", b.shadelsPerMetre, kDensityRange));
    requireCount("--rounds", b.rounds, 1, 100);
    if (b.compareStreaming) {
        if (!(b.textureBudgetMiB > 0.0))
            throw InputError("--streaming-compare: needs a --texture-budget above 0 MiB");
        throwIf(checkFiniteInRange("--texture-budget", b.textureBudgetMiB, kTextureBudgetRange));
    }
    if (b.cpuScopes && b.instanceScaling.empty())
        throw InputError("bench --cpu-scopes: only with --instance-scaling (the other benches "
                         "choose their own)");
    if (!b.instanceScaling.empty() && b.instances != 0)
        throw InputError("--instances: not with --instance-scaling (which sets the counts)");
    if (b.instances != 0) requireCount("--instances", b.instances, 1, 1000000);
    if (b.spectra != Spectra::Auto && b.spectra != Spectra::Off)
        throw InputError("bench --spectra: expected auto, off or compare");
}

int exitForParseError(const CLI::App& app, const CLI::ParseError& error) {
    // --help, --help-all and --version are "errors" with exit code 0 that print their text.
    if (error.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(error);
    std::fprintf(stderr, "shadel: %s (see --help)\n", oneLine(error.what()).c_str());
    return kExitBadInput;
}

} // namespace shadel
