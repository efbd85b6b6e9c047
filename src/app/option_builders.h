#pragma once
// Declaring the options of the table (app/option_table.h): one call per option, from the
// member it sets and its range or choices; the parse, check, echo and --help text follow.
#include <cmath>
#include <cstdlib>
#include <type_traits>

#include "app/cli_validate.h"
#include "app/commands.h"
#include "app/option_table.h"

namespace shadel {

// The member an option sets, for a mutable or a read-only target.
#define SETTING(member)                                                                            \
    [](auto& t) -> auto& {                                                                         \
        return t.settings.member;                                                                  \
    }

// The number `text`, or InputError "<flag> <text>: not a number".
double parseNumber(const char* flag, const std::string& text);

std::string rangeText(FloatRange r); // "FINITE [min, max]"

template <class Access>
SettingOption floatOption(const char* flag, Access access, FloatRange range, uint32_t commands,
                          const char* help) {
    SettingOption o{flag, help, commands, rangeText(range)};
    o.parse = [=](OptionTarget t, const std::string& text) {
        double v = parseNumber(flag, text);
        if (std::string problem = checkFiniteInRange(flag, v, range); !problem.empty())
            throw InputError(problem);
        access(t) = static_cast<std::remove_reference_t<decltype(access(t))>>(v);
    };
    o.json = [=](ConstOptionTarget t) { return nlohmann::json(access(t)); };
    o.text = [=](ConstOptionTarget t) { return format("%g", double(access(t))); };
    o.check = [=](ConstOptionTarget t) {
        return checkFiniteInRange(flag, double(access(t)), range);
    };
    return o;
}

template <class Access>
SettingOption countOption(const char* flag, Access access, uint32_t lo, uint32_t hi,
                          uint32_t commands, const char* help) {
    SettingOption o{flag, help, commands, format("%u..%u", lo, hi)};
    o.parse = [=](OptionTarget t, const std::string& text) {
        char* end = nullptr;
        unsigned long long v = std::strtoull(text.c_str(), &end, 10);
        if (text.empty() || text[0] == '-' || end != text.c_str() + text.size() || v < lo || v > hi)
            throw InputError(format("%s %s: expected %u..%u", flag, text.c_str(), lo, hi));
        access(t) = uint32_t(v);
    };
    o.json = [=](ConstOptionTarget t) { return nlohmann::json(access(t)); };
    o.text = [=](ConstOptionTarget t) { return std::to_string(access(t)); };
    o.check = [=](ConstOptionTarget t) {
        uint32_t v = access(t);
        return v < lo || v > hi ? format("%s %u: expected %u..%u", flag, v, lo, hi) : std::string();
    };
    return o;
}

// One of named values; on/off options are bool choices and echo as JSON bools.
template <class T, class Access>
SettingOption choiceOption(const char* flag, Access access, Choices<T> choices, uint32_t commands,
                           const char* help) {
    std::string accepted;
    for (const auto& [name, value] : choices)
        accepted += (accepted.empty() ? "" : " | ") + std::string(name);
    SettingOption o{flag, help, commands, accepted};
    o.parse = [=](OptionTarget t, const std::string& text) {
        access(t) = parseChoice(flag, text, choices);
    };
    auto name = [=](const T& value) -> const char* {
        for (const auto& [n, v] : choices)
            if (v == value) return n;
        return nullptr;
    };
    o.text = [=](ConstOptionTarget t) {
        const char* n = name(access(t));
        return std::string(n ? n : "?");
    };
    o.json = [=](ConstOptionTarget t) {
        if constexpr (std::is_same_v<T, bool>) return nlohmann::json(bool(access(t)));
        const char* n = name(access(t));
        return nlohmann::json(n ? n : "?");
    };
    o.check = [=](ConstOptionTarget t) {
        return name(access(t))
                   ? std::string()
                   : format("%s %d: not one of %s", flag, int(access(t)), accepted.c_str());
    };
    return o;
}

template <class Access>
SettingOption onOffOption(const char* flag, Access access, uint32_t commands, const char* help) {
    return choiceOption<bool>(flag, access, {{"on", true}, {"off", false}}, commands, help);
}

// A flag without a value: given means true.
template <class Access>
SettingOption switchOption(const char* flag, Access access, uint32_t commands, const char* help) {
    SettingOption o{flag, help, commands, ""};
    o.parse = [=](OptionTarget t, const std::string&) { access(t) = true; };
    o.json = [=](ConstOptionTarget t) { return nlohmann::json(bool(access(t))); };
    o.text = [=](ConstOptionTarget t) { return std::string(access(t) ? "true" : "false"); };
    o.check = [](ConstOptionTarget) { return std::string(); };
    return o;
}

// An X,Y pixel option (-1,-1: none) writing two int32 members.
template <class AccessX, class AccessY>
SettingOption pixelOption(const char* flag, AccessX ax, AccessY ay, const char* help) {
    SettingOption o{flag, help, kRenderCommand, "none | X,Y"};
    o.parse = [=](OptionTarget t, const std::string& text) {
        if (text == "none")
            ax(t) = ay(t) = -1;
        else
            parsePixel(flag, text, ax(t), ay(t));
    };
    o.text = [=](ConstOptionTarget t) {
        return ax(t) < 0 ? std::string("none") : format("%d,%d", ax(t), ay(t));
    };
    o.json = [=](ConstOptionTarget t) {
        return ax(t) < 0 ? nlohmann::json(nullptr) : nlohmann::json({ax(t), ay(t)});
    };
    o.check = [](ConstOptionTarget) { return std::string(); }; // against the size: validate()
    return o;
}

// Options with a text form of their own (option_builders.cpp).
SettingOption exposureOption();     // --exposure EV (the settings hold 2^EV)
SettingOption environmentOption();  // --environment builtin:sky|none|FILE
SettingOption backgroundOption();   // --background environment|R,G,B
SettingOption sizeOption();         // --size WIDTHxHEIGHT
SettingOption debugLinesOption();   // --debug-lines none|KIND[,KIND...]
SettingOption shuffleDrawsOption(); // --shuffle-draws SEED

} // namespace shadel
