#pragma once
// Command-line checks shared by every subcommand's flag definitions: floats must be finite and
// in range (NaN and infinity parse as floats, then silently render black or garbage), and every
// command-line error, the CLI11 parser's own included, is one line on stderr and exit code 2.
#include <string>

#include <CLI/CLI.hpp>

namespace shadel {

// Exit code for bad input (README): flags, files, scenes.
constexpr int kExitBadInput = 2;

// Accepts a finite number in [min, max] (or (min, max] when minExclusive). CLI11 reports a
// rejection as "<flag>: <reason>".
CLI::Validator finiteInRange(double min, double max, bool minExclusive = false);

// Accepts a byte size: digits with an optional k, M, G or T (binary) suffix, e.g. 4G.
CLI::Validator byteSize();

// The same check for values set in code; "" or "<flag> <value>: <reason>".
std::string checkFiniteInRange(const char* flag, double value, double min, double max,
                               bool minExclusive = false);

// What main returns for a CLI11 exception: help and version print and return 0; any other
// error prints "shadel: <message>" on one line and returns kExitBadInput.
int exitForParseError(const CLI::App& app, const CLI::ParseError& error);

} // namespace shadel
