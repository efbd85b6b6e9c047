#pragma once
// Command-line checks shared by every subcommand's flag definitions: floats must be finite and
// in range (NaN and infinity parse as floats, then silently render black or garbage), and every
// command-line error, the CLI11 parser's own included, is one line on stderr and exit code 2.
#include <string>

#include <CLI/CLI.hpp>
#include <glm/glm.hpp>

namespace shadel {

// Exit code for bad input (README): flags, files, scenes.
constexpr int kExitBadInput = 2;

// [min, max], or (min, max] when minExclusive.
struct FloatRange {
    double min, max;
    bool minExclusive = false;
};

// The accepted values of the float flags, shared by the flag definitions and validate()
// (in-process callers bypass the parser).
constexpr FloatRange kDensityRange{0, 1e6};             // shadels per metre; 0 = auto (view-driven)
constexpr FloatRange kFixedDensityRange{0, 1e6, true};  // shadels per metre (bake: no auto)
constexpr FloatRange kShadingBiasRange{-8, 8};          // MIP levels
constexpr FloatRange kTrilinearBandRange{0, 1};         // fraction of a MIP level
constexpr FloatRange kShadelBudgetRange{0, 1e12, true}; // MIP-0 shadels
constexpr FloatRange kForwardBelowRange{0, 1e12};       // pixels; 0 = never
constexpr FloatRange kFovRange{0, 179, true};           // degrees, vertical
constexpr FloatRange kTimeRange{0, 1e6};                // seconds (--time)
constexpr FloatRange kTimeStepRange{0, 3600, true};     // seconds per frame (--time-step)
constexpr FloatRange kCoordinateRange{-1e9, 1e9};       // world units (--from, --look-at)
constexpr FloatRange kTextureBudgetRange{0, 1e6, true}; // MiB (--texture-budget)
constexpr FloatRange kDfDistanceRange{0, 1e6}; // metres (--df-shadow-start, --df-residency)

// Accepts a finite number in the range. CLI11 reports a rejection as "<flag>: <reason>".
CLI::Validator finiteInRange(FloatRange range);

// Accepts "X,Y,Z": three finite numbers in `range`, nothing else.
CLI::Validator finiteVec3(FloatRange range);
// Parses what finiteVec3 accepted (throws InputError naming the flag otherwise).
glm::vec3 parseVec3(const char* flag, const std::string& text, FloatRange range);

// Accepts a byte size: digits with an optional k, M, G or T (binary) suffix, e.g. 4G.
CLI::Validator byteSize();

// The same check for values set in code; "" or "<flag> <value>: <reason>".
std::string checkFiniteInRange(const char* flag, double value, FloatRange range);

struct RenderOptions;
struct BenchOptions;
// Every rule about a command's options in one place: throws InputError naming the flag for the
// first value out of range (the option table's settings, then the command's own options) or
// option that needs another. Runs on what the command line set and on what code set (tests and
// the bench call runRender without the flag parser), before the scene is loaded.
void validate(const RenderOptions& options);
void validate(const BenchOptions& options);

// What main returns for a CLI11 exception: help and version print and return 0; any other
// error prints "shadel: <message>" on one line and returns kExitBadInput.
int exitForParseError(const CLI::App& app, const CLI::ParseError& error);

} // namespace shadel
