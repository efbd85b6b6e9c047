#pragma once
// Strict parsing of whole numbers from the command line and text formats: digits only (no sign,
// no spaces, no exponent), and a value above the caller's bound is an error instead of wrapping
// (sscanf's %u takes 4294967616 as 320).
#include <cstdint>
#include <optional>
#include <string_view>

namespace shadel {

// The value of `text` if it is one or more decimal digits and at most maxValue.
std::optional<uint64_t> parseWholeNumber(std::string_view text, uint64_t maxValue = UINT64_MAX);

// Two whole numbers separated by one of `separators` ("x" for 1280x720, "," for 40,20).
std::optional<std::pair<uint64_t, uint64_t>>
parseWholeNumberPair(std::string_view text, std::string_view separators, uint64_t maxValue);

} // namespace shadel
