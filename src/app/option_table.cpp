#include "app/option_table.h"

namespace shadel {

std::string expectedChoices(const std::vector<const char*>& names) {
    std::string text;
    for (size_t i = 0; i < names.size(); ++i) {
        if (i) text += i + 1 == names.size() ? " or " : ", ";
        text += names[i];
    }
    return text;
}

void addSettingFlags(CLI::App& sub, uint32_t command, SettingFlags& flags) {
    const RenderSettings defaults;
    const ConstOptionTarget defaultTarget{defaults, true};
    for (const SettingOption& option : settingOptions()) {
        if (!(option.commands & command)) continue;
        flags.texts.push_back(std::make_unique<std::string>());
        std::string& text = *flags.texts.back();
        std::string help = option.help;
        CLI::Option* added = nullptr;
        if (option.accepted.empty()) { // a plain flag: given means on
            added = sub.add_flag(option.flag)->description(help);
        } else {
            help = option.accepted + ": " + help;
            added = sub.add_option(option.flag, text, help)
                        ->default_str(option.text(defaultTarget))
                        ->type_name("");
        }
        flags.options.push_back({&option, added});
    }
}

void applySettingFlags(const SettingFlags& flags, OptionTarget target) {
    for (size_t i = 0; i < flags.options.size(); ++i) {
        const auto& [option, cli] = flags.options[i];
        if (cli->count() > 0) option->parse(target, *flags.texts[i]);
    }
}

void parseSetting(const char* flag, const std::string& text, OptionTarget target) {
    for (const SettingOption& option : settingOptions())
        if (std::string(option.flag) == flag) return option.parse(target, text);
    throw std::logic_error(std::string("parseSetting: no option ") + flag);
}

std::string checkSettings(ConstOptionTarget target, uint32_t command) {
    for (const SettingOption& option : settingOptions())
        if (option.commands & command)
            if (std::string problem = option.check(target); !problem.empty()) return problem;
    return {};
}

nlohmann::json settingsJson(ConstOptionTarget target, uint32_t command) {
    nlohmann::json out = nlohmann::json::object();
    for (const SettingOption& option : settingOptions())
        if (option.commands & command) out[option.flag + 2] = option.json(target);
    return out;
}

} // namespace shadel
