#pragma once
// `shadel SUBCOMMAND --help` lists only that subcommand's flags by default, yet the global ones
// (--device, --validation, ...) are accepted there too: they are appended to every subcommand's
// help, with the bake cache folder in use.
#include <CLI/CLI.hpp>

namespace shadel {

// Call after every flag and subcommand is defined. Also lets global flags follow the
// subcommand name (`shadel render --device cpu`).
void showGlobalFlagsInSubcommandHelp(CLI::App& app);

} // namespace shadel
