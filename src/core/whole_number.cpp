#include "core/whole_number.h"

#include <utility>

namespace shadel {

std::optional<uint64_t> parseWholeNumber(std::string_view text, uint64_t maxValue) {
    if (text.empty()) return std::nullopt;
    uint64_t value = 0;
    for (char c : text) {
        if (c < '0' || c > '9') return std::nullopt;
        uint64_t digit = uint64_t(c - '0');
        if (value > (maxValue - digit) / 10) return std::nullopt; // value * 10 + digit > max
        value = value * 10 + digit;
    }
    return value;
}

std::optional<std::pair<uint64_t, uint64_t>>
parseWholeNumberPair(std::string_view text, std::string_view separators, uint64_t maxValue) {
    size_t at = text.find_first_of(separators);
    if (at == std::string_view::npos) return std::nullopt;
    std::optional<uint64_t> a = parseWholeNumber(text.substr(0, at), maxValue);
    std::optional<uint64_t> b = parseWholeNumber(text.substr(at + 1), maxValue);
    if (!a || !b) return std::nullopt;
    return std::pair{*a, *b};
}

} // namespace shadel
