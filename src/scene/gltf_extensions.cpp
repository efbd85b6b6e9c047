#include "scene/gltf_extensions.h"

#include <algorithm>
#include <set>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/log.h"

namespace shadel {

namespace {

// Sorted: looked up with binary search. Each one is applied by the importer or the shared
// material code; nothing here is "accepted and ignored".
constexpr std::string_view kSupported[] = {
    "EXT_meshopt_compression",    "KHR_lights_punctual",
    "KHR_materials_clearcoat",    "KHR_materials_emissive_strength",
    "KHR_materials_ior",          "KHR_materials_pbrSpecularGlossiness",
    "KHR_materials_sheen",        "KHR_materials_specular",
    "KHR_materials_transmission", "KHR_materials_unlit",
    "KHR_materials_volume",       "KHR_mesh_quantization",
    "KHR_texture_transform",
};

void collectKeys(const nlohmann::json& obj, std::set<std::string>& out) {
    if (!obj.is_object()) return;
    auto ext = obj.find("extensions");
    if (ext == obj.end() || !ext->is_object()) return;
    for (auto it = ext->begin(); it != ext->end(); ++it)
        if (!gltfExtensionSupported(it.key())) out.insert(it.key());
}

// Texture infos (objects with an "index") one level below a material or its extension objects.
void collectMaterialKeys(const nlohmann::json& material, std::set<std::string>& out) {
    collectKeys(material, out);
    if (!material.is_object()) return;
    auto visitTextureInfos = [&](const nlohmann::json& obj) {
        if (!obj.is_object()) return;
        for (auto it = obj.begin(); it != obj.end(); ++it)
            if (it->is_object() && it->contains("index")) collectKeys(*it, out);
    };
    visitTextureInfos(material);
    if (auto pbr = material.find("pbrMetallicRoughness"); pbr != material.end())
        visitTextureInfos(*pbr);
    if (auto ext = material.find("extensions"); ext != material.end() && ext->is_object())
        for (auto it = ext->begin(); it != ext->end(); ++it) visitTextureInfos(*it);
}

} // namespace

bool gltfExtensionSupported(std::string_view name) {
    return std::binary_search(std::begin(kSupported), std::end(kSupported), name);
}

void checkRequiredGltfExtensions(const nlohmann::json& root, const std::string& input) {
    auto required = root.find("extensionsRequired");
    if (required == root.end() || !required->is_array()) return;
    for (const nlohmann::json& ext : *required) {
        if (!ext.is_string()) continue;
        const std::string& name = ext.get_ref<const std::string&>();
        if (!gltfExtensionSupported(name))
            throw InputError(input + ": required extension " + name + " is not supported");
    }
}

std::vector<std::string> ignoredGltfExtensions(const nlohmann::json& root) {
    std::set<std::string> out;
    if (!root.is_object()) return {};
    if (auto used = root.find("extensionsUsed"); used != root.end() && used->is_array())
        for (const nlohmann::json& ext : *used)
            if (ext.is_string() && !gltfExtensionSupported(ext.get_ref<const std::string&>()))
                out.insert(ext.get<std::string>());
    collectKeys(root, out);
    auto each = [&](const char* array, auto&& visit) {
        auto list = root.find(array);
        if (list == root.end() || !list->is_array()) return;
        for (const nlohmann::json& item : *list) visit(item);
    };
    for (const char* array : {"nodes", "textures", "images", "accessors", "bufferViews", "buffers",
                              "cameras", "samplers", "scenes", "skins", "animations"})
        each(array, [&](const nlohmann::json& item) { collectKeys(item, out); });
    each("materials", [&](const nlohmann::json& m) { collectMaterialKeys(m, out); });
    each("meshes", [&](const nlohmann::json& mesh) {
        collectKeys(mesh, out);
        if (!mesh.is_object()) return;
        auto prims = mesh.find("primitives");
        if (prims == mesh.end() || !prims->is_array()) return;
        for (const nlohmann::json& prim : *prims) collectKeys(prim, out);
    });
    return {out.begin(), out.end()};
}

std::string ignoredExtensionsWarning(const std::vector<std::string>& ignored) {
    if (ignored.empty()) return {};
    std::string list;
    for (const std::string& name : ignored) list += (list.empty() ? "" : ", ") + name;
    return format("extension%s not supported, ignored (the scene may look different): %s",
                  ignored.size() > 1 ? "s" : "", list.c_str());
}

} // namespace shadel
