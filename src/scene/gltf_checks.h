#pragma once
// The glTF importer's first gate: checks of the raw JSON before tinygltf sees it, because
// tinygltf silently ignores wrongly typed optional properties and trusts the ranges it later
// slices image data with. Every failure throws InputError "<input>: <reason>".
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace shadel::gltf {

nlohmann::json parseJson(std::string_view text, const std::string& input);

// Refuses element counts no renderable scene has, in time linear in the counts.
void checkCounts(const nlohmann::json& root, const std::string& input);

// Refuses buffer and image URIs that leave the model's folder (unless allowed): a model is a
// folder of files, and reading `../../etc/passwd` or `/home/...` on its behalf is never intended.
void checkUrisStayInFolder(const nlohmann::json& root, const std::string& input);

// Checks types and index ranges of every property the importer (or tinygltf) reads, so that
// a wrongly typed value is an error instead of being silently replaced by a default.
void checkSchema(const nlohmann::json& root, const std::string& input);

} // namespace shadel::gltf
