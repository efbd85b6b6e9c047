#pragma once
// EXT_meshopt_compression (meshoptimizer's decoder). A compressed file's "fallback" buffers
// hold no bytes in the file: the compressed buffer views decode into them. Two steps around
// tinygltf (which would refuse a buffer without data):
//  1. prepareMeshopt, on the checked JSON: checks every extension object (types, ranges, modes,
//     filters), bounds the bytes the fallbacks will take (at most kMaxMeshoptExpansion times
//     the compressed bytes, so memory stays linear in the input), and gives each fallback
//     buffer a one-byte placeholder;
//  2. decodeMeshopt, on the loaded model: sizes the fallbacks and decodes every compressed view
//     into its place, checking each source and destination range and the decoder's result.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

namespace shadel {

// meshoptimizer's codecs reach about 64:1 on constant data; a declared size beyond this many
// times the compressed bytes is refused.
constexpr uint64_t kMaxMeshoptExpansion = 128;

struct MeshoptPlan {
    struct Fallback {
        size_t buffer;
        uint64_t byteLength;
    };
    std::vector<Fallback> fallbacks;
    bool any = false; // some buffer view is compressed
};

// Throws InputError "<input>: <pointer>: <reason>". Rewrites `document` only when it returns
// a plan with fallbacks.
MeshoptPlan prepareMeshopt(nlohmann::json& document, const std::string& input);

void decodeMeshopt(const MeshoptPlan& plan, tinygltf::Model& model, const std::string& input);

} // namespace shadel
