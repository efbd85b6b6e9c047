#pragma once
// The version of the stats layout: the "schema" key of `render --stats` and of `bench --json`.
// Bumped when a key is renamed or removed or changes meaning; adding a key keeps it
// (docs/stats.md explains every key; docs/stats.schema.json lists them and their types).
#include <string>

#include <nlohmann/json.hpp>

namespace shadel {

constexpr int kStatsSchemaVersion = 1;

// Writes a bench JSON to `path` (nothing when empty) with "schema": kStatsSchemaVersion added:
// its modes.<name> objects are render stats of that layout.
void writeBenchJson(const std::string& path, nlohmann::json& out);

} // namespace shadel
