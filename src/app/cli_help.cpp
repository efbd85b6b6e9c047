#include "app/cli_help.h"

#include <vector>

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
    app.footer([] { return "Cache folder: " + defaultCacheFolder(); });
    // Nested subcommands too (`shadel cache clean --help`).
    std::vector<CLI::App*> pending = app.get_subcommands({});
    while (!pending.empty()) {
        CLI::App* sub = pending.back();
        pending.pop_back();
        sub->fallthrough();
        sub->footer([text] { return text + "Cache folder: " + defaultCacheFolder(); });
        for (CLI::App* nested : sub->get_subcommands({})) pending.push_back(nested);
    }
}

} // namespace shadel
