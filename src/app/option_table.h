#pragma once
// The options of `shadel render`, `bench` and `view` that set the renderer's settings, each
// declared once (option_entries.cpp): its flag, the RenderSettings member it sets (or the scene
// file option, --sun), the accepted range or choices, its help and the subcommands that take it.
// The default is the member's default initialiser, read from a default RenderSettings. The
// command-line registration, the parse and range check of the flag's text, the check of values
// set in code (validate) and the "settings" echo in stats and bench JSON come from the table.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/log.h"
#include "render/renderer.h"

namespace shadel {

// The subcommands an option belongs to (a mask).
enum OptionCommand : uint32_t { kRenderCommand = 1, kBenchCommand = 2, kViewCommand = 4 };
constexpr uint32_t kEveryRenderingCommand = kRenderCommand | kBenchCommand | kViewCommand;

// What a table option writes: the renderer's settings, and how a scene file is imported.
struct OptionTarget {
    RenderSettings& settings;
    bool& addDefaultSun; // SceneFileOptions::addDefaultSun (--sun)
};
struct ConstOptionTarget {
    const RenderSettings& settings;
    bool addDefaultSun;
};

struct SettingOption {
    const char* flag; // "--shading-bias"
    const char* help; // what it does; the accepted values and the default are added to it
    uint32_t commands = kRenderCommand;
    // The accepted values as --help shows them: "on | off", "FINITE [-8, 8]", "1..64".
    std::string accepted;
    // Parses the flag's text into the target; throws InputError "<flag> <text>: <reason>".
    std::function<void(OptionTarget, const std::string&)> parse;
    // The current value as JSON (a number, a bool for on/off, the choice's name).
    std::function<nlohmann::json(ConstOptionTarget)> json;
    // The current value as the flag's text, the form parse reads back (--help's default).
    std::function<std::string(ConstOptionTarget)> text;
    // "" or "<flag> <value>: <reason>" for a value set in code (tests, bench).
    std::function<std::string(ConstOptionTarget)> check;
};

// Every option of the table, in --help order.
const std::vector<SettingOption>& settingOptions();

// A choice option's names and values ("on" -> true, "aces-hill" -> Tonemap::AcesHill).
template <class T>
using Choices = std::vector<std::pair<const char*, T>>;
// The value named `text`, or InputError "<flag> <text>: expected a, b or c".
std::string expectedChoices(const std::vector<const char*>& names); // "a, b or c"
template <class T>
T parseChoice(const char* flag, const std::string& text, const Choices<T>& c) {
    std::vector<const char*> names;
    for (const auto& [name, value] : c) {
        if (text == name) return value;
        names.push_back(name);
    }
    throw InputError(
        format("%s %s: expected %s", flag, text.c_str(), expectedChoices(names).c_str()));
}

// The table's options of `command`, added to `sub`; the text of the ones given on the command
// line is kept until applySettingFlags parses it into a target.
struct SettingFlags {
    std::vector<std::pair<const SettingOption*, CLI::Option*>> options;
    std::vector<std::unique_ptr<std::string>> texts; // one per option, CLI11 writes here
};
void addSettingFlags(CLI::App& sub, uint32_t command, SettingFlags& flags);
// Parses each option given on the command line, in table order (first error thrown).
void applySettingFlags(const SettingFlags& flags, OptionTarget target);

// Parses `text` as the table's option `flag` into the target (std::logic_error for a flag not
// in the table).
void parseSetting(const char* flag, const std::string& text, OptionTarget target);

// The first table option of `command` whose value in `target` is out of range, or "".
std::string checkSettings(ConstOptionTarget target, uint32_t command);
// Every table option of `command` as JSON, keyed by flag name without the dashes.
nlohmann::json settingsJson(ConstOptionTarget target, uint32_t command);

} // namespace shadel
