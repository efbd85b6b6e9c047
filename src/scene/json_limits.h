#pragma once
// Bounds on a glTF's JSON that are checked in time linear in the file size, before any tree is
// built from it (a hostile file must not make parsing quadratic or exhaust memory).
#include <cstddef>
#include <string_view>

namespace shadel {

// The deepest nesting of objects and arrays in `text`, counted in one pass that skips strings
// (brackets inside string values do not nest). Stops early and returns limit + 1 as soon as
// the nesting exceeds `limit`. Malformed JSON is not diagnosed here (the parser does that).
size_t jsonNestingDepth(std::string_view text, size_t limit);

} // namespace shadel
