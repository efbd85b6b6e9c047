#include "app/option_builders.h"

#include <cctype>
#include <cstdio>
#include <filesystem>

#include "app/commands.h"
#include "core/whole_number.h"

namespace shadel {

double parseNumber(const char* flag, const std::string& text) {
    char* end = nullptr;
    double v = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size())
        throw InputError(format("%s %s: not a number", flag, text.c_str()));
    return v;
}

std::string rangeText(FloatRange r) {
    return format("FINITE %s%g, %g]", r.minExclusive ? "(" : "[", r.min, r.max);
}

// --exposure EV: the settings hold the linear multiplier 2^EV.
constexpr FloatRange kExposureEvRange{-20, 20}; // EV; 2^20 ~ 1e6, as the linear cap was
SettingOption exposureOption() {
    SettingOption o{"--exposure",
                    "exposure in EV, before the tone curve (0: x1, +1: twice as bright)",
                    kEveryRenderingCommand, rangeText(kExposureEvRange)};
    o.parse = [](OptionTarget t, const std::string& text) {
        double ev = parseNumber("--exposure", text);
        if (std::string problem = checkFiniteInRange("--exposure", ev, kExposureEvRange);
            !problem.empty())
            throw InputError(problem);
        t.settings.exposure = float(std::exp2(ev));
    };
    auto ev = [](ConstOptionTarget t) { return std::log2(double(t.settings.exposure)); };
    o.json = [=](ConstOptionTarget t) { return nlohmann::json(ev(t)); };
    o.text = [=](ConstOptionTarget t) { return format("%g", ev(t)); };
    o.check = [=](ConstOptionTarget t) {
        return checkFiniteInRange("--exposure", ev(t), kExposureEvRange);
    };
    return o;
}

// "" or why `name` is not builtin:sky, none or an existing .hdr / .exr file.
static std::string environmentProblem(const std::string& name) {
    if (name == "builtin:sky" || name == "none") return {};
    std::string ext = std::filesystem::path(name).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".hdr" && ext != ".exr")
        return format("--environment %s: expected builtin:sky, none or an equirectangular .hdr "
                      "or .exr file",
                      name.c_str());
    std::error_code ec;
    if (!std::filesystem::is_regular_file(name, ec))
        return format("--environment %s: no such file", name.c_str());
    return {};
}

SettingOption environmentOption() {
    SettingOption o{"--environment",
                    "image-based lighting: a physically based sky lit by the scene's sun, none, "
                    "or an equirectangular .hdr / .exr file (default: the sky, or the scene's "
                    "authored sky and ambient colour)",
                    kEveryRenderingCommand, "builtin:sky | none | FILE"};
    o.parse = [](OptionTarget t, const std::string& text) {
        if (std::string problem = environmentProblem(text); !problem.empty())
            throw InputError(problem);
        t.settings.environment = text;
        t.settings.environmentGiven = true;
    };
    o.json = [](ConstOptionTarget t) { return nlohmann::json(t.settings.environment); };
    o.text = [](ConstOptionTarget t) { return t.settings.environment; };
    o.check = [](ConstOptionTarget t) { return environmentProblem(t.settings.environment); };
    return o;
}

constexpr FloatRange kColourRange{0, 1};
static std::string backgroundProblem(const std::string& text, glm::vec3& colour) {
    const char* p = text.c_str();
    for (int i = 0; i < 3; ++i) {
        char* end = nullptr;
        double v = std::strtod(p, &end);
        if (end == p || (i < 2 && *end != ',') || (i == 2 && *end != '\0') ||
            !checkFiniteInRange("", v, kColourRange).empty())
            return format("--background %s: expected environment or R,G,B (sRGB, each 0..1)",
                          text.c_str());
        colour[i] = float(v);
        p = end + 1;
    }
    return {};
}

SettingOption backgroundOption() {
    SettingOption o{"--background",
                    "behind the scene: the environment, or a solid sRGB colour (each 0..1)",
                    kEveryRenderingCommand, "environment | R,G,B"};
    o.parse = [](OptionTarget t, const std::string& text) {
        if (text == "environment") {
            t.settings.backgroundEnvironment = true;
            return;
        }
        glm::vec3 colour(0.0f);
        if (std::string problem = backgroundProblem(text, colour); !problem.empty())
            throw InputError(problem);
        t.settings.backgroundEnvironment = false;
        t.settings.backgroundColor = colour;
    };
    o.text = [](ConstOptionTarget t) {
        const glm::vec3& c = t.settings.backgroundColor;
        return t.settings.backgroundEnvironment
                   ? std::string("environment")
                   : format("%g,%g,%g", double(c.r), double(c.g), double(c.b));
    };
    o.json = [](ConstOptionTarget t) {
        const glm::vec3& c = t.settings.backgroundColor;
        return t.settings.backgroundEnvironment ? nlohmann::json("environment")
                                                : nlohmann::json({c.r, c.g, c.b});
    };
    o.check = [](ConstOptionTarget t) {
        glm::vec3 colour;
        return t.settings.backgroundEnvironment
                   ? std::string()
                   : backgroundProblem(format("%.9g,%.9g,%.9g",
                                              double(t.settings.backgroundColor.r),
                                              double(t.settings.backgroundColor.g),
                                              double(t.settings.backgroundColor.b)),
                                       colour);
    };
    return o;
}

SettingOption sizeOption() {
    SettingOption o{"--size", "image size in pixels (each side 1..16384)", kEveryRenderingCommand,
                    "WIDTHxHEIGHT"};
    o.parse = [](OptionTarget t, const std::string& text) {
        auto size = parseWholeNumberPair(text, "xX", UINT64_MAX);
        if (!size)
            throw InputError(
                format("--size %s: expected WIDTHxHEIGHT, e.g. 1280x720", text.c_str()));
        auto [w, h] = *size;
        if (w < 1 || h < 1 || w > 16384 || h > 16384)
            throw InputError(
                format("--size %s: each side must be between 1 and 16384", text.c_str()));
        t.settings.width = uint32_t(w), t.settings.height = uint32_t(h);
    };
    o.text = [](ConstOptionTarget t) {
        return format("%ux%u", t.settings.width, t.settings.height);
    };
    o.json = [](ConstOptionTarget t) {
        return nlohmann::json({t.settings.width, t.settings.height});
    };
    o.check = [](ConstOptionTarget t) {
        uint32_t w = t.settings.width, h = t.settings.height;
        return w < 1 || h < 1 || w > 16384 || h > 16384
                   ? format("--size %ux%u: each side must be between 1 and 16384", w, h)
                   : std::string();
    };
    return o;
}

SettingOption debugLinesOption() {
    SettingOption o{"--debug-lines",
                    "3-D lines drawn over the frame, emitted by shaders: lights (ranges, "
                    "cones), blockers (rectangles, portals, shadow frusta), chunks (world boxes "
                    "of the shadel chunks shaded)",
                    kRenderCommand, "none | KIND[,KIND...]"};
    o.parse = [](OptionTarget t, const std::string& text) {
        t.settings.debugLines = parseDebugLines(text);
    };
    o.text = [](ConstOptionTarget t) {
        std::string names;
        for (auto [bit, name] :
             {std::pair{DEBUG_LINES_LIGHTS, "lights"}, std::pair{DEBUG_LINES_BLOCKERS, "blockers"},
              std::pair{DEBUG_LINES_CHUNKS, "chunks"}})
            if (t.settings.debugLines & uint32_t(bit))
                names += (names.empty() ? "" : ",") + std::string(name);
        return names.empty() ? std::string("none") : names;
    };
    o.json = [o](ConstOptionTarget t) { return nlohmann::json(o.text(t)); };
    o.check = [](ConstOptionTarget) { return std::string(); };
    return o;
}

SettingOption shuffleDrawsOption() {
    SettingOption o{"--shuffle-draws",
                    "draw the transparent instances in a random order (order independence "
                    "tests)",
                    kRenderCommand, "none | SEED"};
    o.parse = [](OptionTarget t, const std::string& text) {
        if (text == "none") {
            t.settings.shuffleDraws = false;
            return;
        }
        std::optional<uint64_t> seed = parseWholeNumber(text);
        if (!seed)
            throw InputError(
                format("--shuffle-draws %s: expected none or a whole number (a random seed)",
                       text.c_str()));
        t.settings.shuffleDraws = true;
        t.settings.shuffleSeed = *seed;
    };
    o.text = [](ConstOptionTarget t) {
        return t.settings.shuffleDraws ? std::to_string(t.settings.shuffleSeed)
                                       : std::string("none");
    };
    o.json = [](ConstOptionTarget t) {
        return t.settings.shuffleDraws ? nlohmann::json(t.settings.shuffleSeed)
                                       : nlohmann::json(nullptr);
    };
    o.check = [](ConstOptionTarget) { return std::string(); };
    return o;
}

} // namespace shadel
