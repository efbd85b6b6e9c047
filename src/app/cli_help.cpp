#include "app/cli_help.h"

#include "app/commands.h"
#include "core/log.h"

namespace shadel {

void showGlobalFlagsInSubcommandHelp(CLI::App& app) {
    std::string text = "Global flags (before or after the subcommand):\n";
    for (const CLI::Option* option : app.get_options()) {
        std::string name = option->get_name(false, true);
        if (name == app.get_help_ptr()->get_name(false, true)) continue;
        std::string value = option->get_type_size() == 0 ? "" : " " + option->get_type_name();
        text += format("  %-28s %s\n", (name + value).c_str(), option->get_description().c_str());
    }
    std::string footer = text;
    app.footer([] { return "Bake cache: " + defaultCacheDir(); });
    for (CLI::App* sub : app.get_subcommands({})) {
        sub->fallthrough();
        sub->footer([footer] { return footer + "Bake cache: " + defaultCacheDir(); });
    }
}

} // namespace shadel
