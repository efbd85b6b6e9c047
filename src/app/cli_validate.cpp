#include "app/cli_validate.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "bake/cache_eviction.h"
#include "core/log.h"

namespace shadel {
namespace {

// "" or why `value` is not a finite number in range.
std::string rangeProblem(double value, double min, double max, bool minExclusive) {
    if (!std::isfinite(value)) return "must be a finite number";
    bool aboveMin = minExclusive ? value > min : value >= min;
    if (!aboveMin || value > max)
        return format("must be in %s%g, %g]", minExclusive ? "(" : "[", min, max);
    return {};
}

std::string oneLine(std::string text) {
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    for (size_t at; (at = text.find('\n')) != std::string::npos;) text.replace(at, 1, "; ");
    return text;
}

} // namespace

CLI::Validator finiteInRange(double min, double max, bool minExclusive) {
    auto check = [=](std::string& text) -> std::string {
        char* end = nullptr;
        double value = std::strtod(text.c_str(), &end);
        if (text.empty() || end != text.c_str() + text.size()) return text + ": not a number";
        std::string problem = rangeProblem(value, min, max, minExclusive);
        return problem.empty() ? problem : text + ": " + problem;
    };
    return CLI::Validator(check, format("FINITE %s%g..%g]", minExclusive ? "(" : "[", min, max));
}

CLI::Validator byteSize() {
    auto check = [](std::string& text) -> std::string {
        uint64_t bytes = 0;
        return parseByteSize(text, bytes) ? std::string()
                                          : text + ": expected a size such as 4G, 512M or 0";
    };
    return CLI::Validator(check, "SIZE");
}

std::string checkFiniteInRange(const char* flag, double value, double min, double max,
                               bool minExclusive) {
    std::string problem = rangeProblem(value, min, max, minExclusive);
    return problem.empty() ? problem : format("%s %g: %s", flag, value, problem.c_str());
}

int exitForParseError(const CLI::App& app, const CLI::ParseError& error) {
    // --help, --help-all and --version are "errors" with exit code 0 that print their text.
    if (error.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(error);
    std::fprintf(stderr, "shadel: %s (see --help)\n", oneLine(error.what()).c_str());
    return kExitBadInput;
}

} // namespace shadel
