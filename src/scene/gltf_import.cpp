// glTF 2.0 import. The file goes through three gates before anything is built from it:
//  1. our own structural check of the raw JSON (types, index ranges, buffer-view ranges, version),
//     because tinygltf silently ignores wrongly typed optional properties and trusts the ranges
//     it later slices image data with;
//  2. tinygltf, which resolves buffers (files, data URIs, the GLB chunk) and images;
//  3. the conversion below, which bounds-checks every accessor it reads and every index.
// Every failure is an InputError "<file>: <reason>"; nothing is read out of bounds.
//
// This translation unit also holds the one definition of tinygltf, stb_image and
// stb_image_write in the project (the PNG writer includes <stb/stb_image_write.h> without
// STB_IMAGE_WRITE_IMPLEMENTATION).

#include "scene/gltf_import.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <string_view>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

// Images larger than this are rejected by stb_image itself (before it allocates).
#define STBI_MAX_DIMENSIONS 16384
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

// Declares tinygltf's types first (tiny_gltf.h guards its declarations, not its implementation).
#include "scene/gltf_animation.h"
#include "scene/gltf_materials.h"
#include "scene/gltf_meshopt.h"

#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_INCLUDE_STB_IMAGE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE_WRITE
#include <tiny_gltf.h>

#include "core/error.h"
#include "core/log.h"
#include "scene/gltf_extensions.h"
#include "scene/gltf_uri.h"
#include "scene/json_limits.h"
#include "scene/mesh_utils.h"

namespace shadel {

namespace {

using json = nlohmann::json;

// Input files (the .gltf/.glb and every external buffer or image) larger than this are refused:
// the engine has no use for them and it bounds the memory a hostile file can make us allocate.
constexpr uint64_t kMaxFileBytes = 1ull << 30;
// More elements than this in one accessor is not a scene this engine can render.
constexpr uint64_t kMaxAccessorCount = 1ull << 24;
// Deeper JSON nesting than this is refused: tinygltf converts "extras" recursively.
constexpr size_t kMaxJsonDepth = 64;
// Element counts beyond any scene this engine renders; refused before tinygltf builds (large)
// structures for each, so a small hostile file cannot take minutes or gigabytes.
struct CountLimit {
    const char* array;
    size_t max;
};
constexpr CountLimit kMaxCounts[] = {
    {"nodes", 1u << 18},       {"meshes", 1u << 16},  {"accessors", 1u << 18},
    {"bufferViews", 1u << 18}, {"buffers", 1u << 12}, {"materials", 1u << 16},
    {"textures", 1u << 16},    {"images", 1u << 14},  {"samplers", 1u << 12},
    {"cameras", 1u << 12},     {"scenes", 1u << 12},  {"skins", 1u << 12},
    {"animations", 1u << 12},
};
// Primitives summed over all meshes (each becomes at least one Mesh).
constexpr size_t kMaxPrimitives = 1u << 18;
constexpr uint64_t kMaxImagePixels = 1ull << 26;

constexpr uint32_t kGlbMagic = 0x46546C67; // "glTF"
constexpr uint32_t kGlbChunkJson = 0x4E4F534A;

[[noreturn]] void fail(const std::string& input, const std::string& reason) {
    throw InputError(input + ": " + reason);
}

// One line, no trailing newline: tinygltf messages end in '\n' and may contain several lines,
// and quote whole data URIs (megabytes of base64), which are abbreviated.
std::string oneLine(std::string text) {
    for (size_t at = text.find("data:"); at != std::string::npos; at = text.find("data:", at + 1)) {
        size_t end = text.find_first_of(" \n\"'", at);
        if (end == std::string::npos) end = text.size();
        if (end - at > 48) text.replace(at, end - at, "<data URI>");
    }
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' '))
        text.pop_back();
    for (char& c : text)
        if (c == '\n' || c == '\r') c = ';';
    return text;
}

std::vector<uint8_t> readWholeFile(const std::string& path, const std::string& input) {
    std::error_code ec;
    auto status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status)) fail(input, "file not found");
    if (!std::filesystem::is_regular_file(status)) fail(input, "not a regular file");
    uint64_t size = std::filesystem::file_size(path, ec);
    if (ec) fail(input, "cannot read file size");
    if (size > kMaxFileBytes)
        fail(input, format("file is %llu bytes, more than the %llu-byte limit",
                           (unsigned long long)size, (unsigned long long)kMaxFileBytes));
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(input, "cannot open file");
    std::vector<uint8_t> bytes(size);
    if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size)))
        fail(input, "read error");
    return bytes;
}

uint32_t readU32(const uint8_t* p) {
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}

// --- Gate 1: the raw JSON ------------------------------------------------------------------

// Returns the JSON text of a .glb (checking the container) or of a .gltf.
std::string_view jsonTextOf(const std::vector<uint8_t>& bytes, bool binary,
                            const std::string& input) {
    if (!binary) return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
    if (bytes.size() < 20) fail(input, "truncated GLB header");
    uint32_t version = readU32(&bytes[4]), length = readU32(&bytes[8]);
    uint32_t chunkLength = readU32(&bytes[12]), chunkType = readU32(&bytes[16]);
    if (version != 2)
        fail(input, format("binary glTF version %u is not supported (need 2)", version));
    if (length > bytes.size())
        fail(input, format("GLB header says %u bytes but the file has %zu (truncated)", length,
                           bytes.size()));
    if (chunkType != kGlbChunkJson) fail(input, "first GLB chunk is not JSON");
    if (uint64_t(chunkLength) + 20 > length) fail(input, "GLB JSON chunk exceeds the file");
    return {reinterpret_cast<const char*>(bytes.data()) + 20, chunkLength};
}

// The same file with its JSON replaced (a .gltf is its JSON; a .glb keeps its other chunks).
std::vector<uint8_t> withJsonText(const std::vector<uint8_t>& bytes, bool binary,
                                  std::string text) {
    if (!binary) return std::vector<uint8_t>(text.begin(), text.end());
    while (text.size() % 4 != 0) text.push_back(' ');
    uint32_t oldChunk = readU32(&bytes[12]);
    size_t rest = 20 + size_t(oldChunk); // checked by jsonTextOf
    std::vector<uint8_t> out(20);
    std::memcpy(out.data(), bytes.data(), 12);
    uint32_t chunk = uint32_t(text.size()), type = kGlbChunkJson;
    std::memcpy(&out[12], &chunk, 4);
    std::memcpy(&out[16], &type, 4);
    out.insert(out.end(), text.begin(), text.end());
    if (rest < bytes.size()) out.insert(out.end(), bytes.begin() + long(rest), bytes.end());
    uint32_t length = uint32_t(out.size());
    std::memcpy(&out[8], &length, 4);
    return out;
}

json parseJson(std::string_view text, const std::string& input) {
    if (text.empty()) fail(input, "empty file");
    // Checked in one pass before parsing: a parser callback (called per value with the value
    // built so far) made parsing quadratic in the number of objects.
    if (jsonNestingDepth(text, kMaxJsonDepth) > kMaxJsonDepth)
        fail(input, format("JSON nested deeper than %zu levels", kMaxJsonDepth));
    try {
        return json::parse(text.begin(), text.end());
    } catch (const json::exception& e) {
        // nlohmann prefixes "[json.exception.parse_error.101] "; keep the useful tail.
        std::string what = e.what();
        size_t bracket = what.find("] ");
        fail(input, "invalid JSON: " +
                        oneLine(bracket != std::string::npos ? what.substr(bracket + 2) : what));
    }
}

// Refuses element counts no renderable scene has (see kMaxCounts), in time linear in the counts.
void checkCounts(const json& root, const std::string& input) {
    if (!root.is_object()) return; // the schema check reports it
    for (const CountLimit& limit : kMaxCounts) {
        auto it = root.find(limit.array);
        if (it != root.end() && it->is_array() && it->size() > limit.max)
            fail(input,
                 format("%zu %s, more than the limit of %zu", it->size(), limit.array, limit.max));
    }
    auto meshes = root.find("meshes");
    if (meshes == root.end() || !meshes->is_array()) return;
    size_t primitives = 0;
    for (const json& mesh : *meshes) {
        if (!mesh.is_object()) continue;
        auto list = mesh.find("primitives");
        if (list != mesh.end() && list->is_array()) primitives += list->size();
    }
    if (primitives > kMaxPrimitives)
        fail(input,
             format("%zu mesh primitives, more than the limit of %zu", primitives, kMaxPrimitives));
}

// Refuses buffer and image URIs that leave the model's folder (unless allowed): a model is a
// folder of files, and reading `../../etc/passwd` or `/home/...` on its behalf is never intended.
void checkUrisStayInFolder(const json& root, const std::string& input) {
    if (!root.is_object()) return;
    for (const char* array : {"buffers", "images"}) {
        auto list = root.find(array);
        if (list == root.end() || !list->is_array()) continue;
        for (size_t i = 0; i < list->size(); ++i) {
            const json& item = (*list)[i];
            auto uri = item.is_object() ? item.find("uri") : item.end();
            if (uri == item.end() || !uri->is_string()) continue;
            const std::string& text = uri->get_ref<const std::string&>();
            if (text.rfind("data:", 0) == 0) continue;
            if (uriEscapesFolder(decodeUriPath(text)))
                fail(input, format("/%s/%zu/uri '%s' points outside the model's folder "
                                   "(--allow-external-files allows it)",
                                   array, i, oneLine(text.substr(0, 200)).c_str()));
        }
    }
}

// Checks types and index ranges of every property the importer (or tinygltf) reads, so that
// a wrongly typed value is an error instead of being silently replaced by a default.
class JsonSchemaCheck {
public:
    JsonSchemaCheck(const json& root, const std::string& input) : root_(root), input_(input) {}

    void run() {
        if (!root_.is_object()) bad("", "the document root must be an object");
        checkAsset();
        optStringArray(root_, "extensionsUsed", "");
        optStringArray(root_, "extensionsRequired", "");
        checkExtensions(root_, "");
        optIndex(root_, "scene", "", "scenes");
        objectArray(root_, "scenes", "", [&](const json& s, const std::string& p) {
            optString(s, "name", p);
            optIndexArray(s, "nodes", p, "nodes");
        });
        objectArray(root_, "nodes", "",
                    [&](const json& n, const std::string& p) { checkNode(n, p); });
        objectArray(root_, "meshes", "",
                    [&](const json& m, const std::string& p) { checkMesh(m, p); });
        objectArray(root_, "accessors", "",
                    [&](const json& a, const std::string& p) { checkAccessor(a, p); });
        objectArray(root_, "bufferViews", "",
                    [&](const json& v, const std::string& p) { checkBufferView(v, p); });
        objectArray(root_, "buffers", "", [&](const json& b, const std::string& p) {
            optString(b, "name", p);
            optString(b, "uri", p);
            requiredUint(b, "byteLength", p, 1);
        });
        objectArray(root_, "materials", "",
                    [&](const json& m, const std::string& p) { checkMaterial(m, p); });
        objectArray(root_, "textures", "", [&](const json& t, const std::string& p) {
            optString(t, "name", p);
            optIndex(t, "sampler", p, "samplers");
            optIndex(t, "source", p, "images");
        });
        objectArray(root_, "images", "",
                    [&](const json& i, const std::string& p) { checkImage(i, p); });
        objectArray(root_, "samplers", "", [&](const json& s, const std::string& p) {
            for (const char* key : {"magFilter", "minFilter", "wrapS", "wrapT"}) optUint(s, key, p);
        });
        objectArray(root_, "cameras", "",
                    [&](const json& c, const std::string& p) { checkCamera(c, p); });
        objectArray(root_, "skins", "", [](const json&, const std::string&) {});
        objectArray(root_, "animations", "", [](const json&, const std::string&) {});
    }

private:
    const json& root_;
    const std::string& input_;

    [[noreturn]] void bad(const std::string& pointer, const std::string& what) {
        fail(input_, (pointer.empty() ? std::string() : pointer + ": ") + what);
    }
    static std::string child(const std::string& p, const std::string& key) { return p + "/" + key; }
    static std::string child(const std::string& p, size_t i) { return p + "/" + std::to_string(i); }

    static const json* member(const json& obj, const char* key) {
        auto it = obj.find(key);
        return it == obj.end() ? nullptr : &*it;
    }
    [[noreturn]] void wrongType(const std::string& p, const char* expected, const json& v) {
        bad(p, format("must be %s (got %s)", expected, v.type_name()));
    }

    size_t rootCount(const char* array) const {
        if (std::string_view(array) == "lights") {
            const json* ext = member(root_, "extensions");
            const json* lights = ext ? member(*ext, "KHR_lights_punctual") : nullptr;
            const json* list = lights ? member(*lights, "lights") : nullptr;
            return list && list->is_array() ? list->size() : 0;
        }
        const json* a = member(root_, array);
        return a && a->is_array() ? a->size() : 0;
    }

    uint64_t uintValue(const json& v, const std::string& p) {
        if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<int64_t>() >= 0))
            wrongType(p, "a non-negative integer", v);
        return v.get<uint64_t>();
    }
    uint64_t requiredUint(const json& obj, const char* key, const std::string& p,
                          uint64_t min = 0) {
        const json* v = member(obj, key);
        if (!v) bad(p, format("missing required '%s'", key));
        uint64_t value = uintValue(*v, child(p, key));
        if (value < min)
            bad(child(p, key), format("must be at least %llu", (unsigned long long)min));
        return value;
    }
    void optUint(const json& obj, const char* key, const std::string& p) {
        if (const json* v = member(obj, key)) uintValue(*v, child(p, key));
    }
    void checkIndexValue(const json& v, const std::string& p, const char* array) {
        uint64_t index = uintValue(v, p);
        size_t count = rootCount(array);
        if (index >= count)
            bad(p, format("index %llu out of range (%zu %s)", (unsigned long long)index, count,
                          array));
    }
    void optIndex(const json& obj, const char* key, const std::string& p, const char* array) {
        if (const json* v = member(obj, key)) checkIndexValue(*v, child(p, key), array);
    }
    void requiredIndex(const json& obj, const char* key, const std::string& p, const char* array) {
        if (!member(obj, key)) bad(p, format("missing required '%s'", key));
        optIndex(obj, key, p, array);
    }
    void optIndexArray(const json& obj, const char* key, const std::string& p, const char* array) {
        const json* v = member(obj, key);
        if (!v) return;
        if (!v->is_array()) wrongType(child(p, key), "an array", *v);
        for (size_t i = 0; i < v->size(); ++i)
            checkIndexValue((*v)[i], child(child(p, key), i), array);
    }
    double numberValue(const json& v, const std::string& p) {
        if (!v.is_number()) wrongType(p, "a number", v);
        double d = v.get<double>();
        if (!std::isfinite(d)) bad(p, "number is not finite");
        return d;
    }
    void optNumber(const json& obj, const char* key, const std::string& p, double min = -HUGE_VAL) {
        if (const json* v = member(obj, key)) {
            if (numberValue(*v, child(p, key)) < min)
                bad(child(p, key), format("must be at least %g", min));
        }
    }
    void optNumberArray(const json& obj, const char* key, const std::string& p, size_t size) {
        const json* v = member(obj, key);
        if (!v) return;
        if (!v->is_array()) wrongType(child(p, key), "an array", *v);
        if (size != 0 && v->size() != size)
            bad(child(p, key), format("must have %zu numbers (has %zu)", size, v->size()));
        for (size_t i = 0; i < v->size(); ++i) numberValue((*v)[i], child(child(p, key), i));
    }
    void optString(const json& obj, const char* key, const std::string& p) {
        if (const json* v = member(obj, key); v && !v->is_string())
            wrongType(child(p, key), "a string", *v);
    }
    void optBool(const json& obj, const char* key, const std::string& p) {
        if (const json* v = member(obj, key); v && !v->is_boolean())
            wrongType(child(p, key), "a boolean", *v);
    }
    void optStringArray(const json& obj, const char* key, const std::string& p) {
        const json* v = member(obj, key);
        if (!v) return;
        if (!v->is_array()) wrongType(child(p, key), "an array", *v);
        for (size_t i = 0; i < v->size(); ++i)
            if (!(*v)[i].is_string()) wrongType(child(child(p, key), i), "a string", (*v)[i]);
    }
    template <typename F>
    void optObject(const json& obj, const char* key, const std::string& p, F&& check) {
        const json* v = member(obj, key);
        if (!v) return;
        if (!v->is_object()) wrongType(child(p, key), "an object", *v);
        check(*v, child(p, key));
    }
    template <typename F>
    void objectArray(const json& obj, const char* key, const std::string& p, F&& check) {
        const json* v = member(obj, key);
        if (!v) return;
        if (!v->is_array()) wrongType(child(p, key), "an array", *v);
        for (size_t i = 0; i < v->size(); ++i) {
            const json& e = (*v)[i];
            if (!e.is_object()) wrongType(child(child(p, key), i), "an object", e);
            check(e, child(child(p, key), i));
        }
    }
    // Every "extensions" value is an object of objects (glTF schema), whatever the extension.
    void checkExtensions(const json& obj, const std::string& p) {
        const json* ext = member(obj, "extensions");
        if (!ext) return;
        if (!ext->is_object()) wrongType(child(p, "extensions"), "an object", *ext);
        for (auto it = ext->begin(); it != ext->end(); ++it)
            if (!it->is_object())
                wrongType(child(child(p, "extensions"), it.key()), "an object", *it);
        if (const json* lights = member(*ext, "KHR_lights_punctual"); lights && &obj == &root_) {
            objectArray(*lights, "lights", child(child(p, "extensions"), "KHR_lights_punctual"),
                        [&](const json& l, const std::string& lp) { checkLight(l, lp); });
        }
    }

    void checkAsset() {
        const json* asset = member(root_, "asset");
        if (!asset) bad("", "missing 'asset' (not a glTF 2.0 file)");
        if (!asset->is_object()) wrongType("/asset", "an object", *asset);
        const json* version = member(*asset, "version");
        if (!version) bad("/asset", "missing 'version' (not a glTF 2.0 file)");
        if (version->is_number()) // glTF 1.0 exporters sometimes wrote the version as a number
            bad("", format("glTF version %s is not supported (need 2.x)", version->dump().c_str()));
        if (!version->is_string()) wrongType("/asset/version", "a string", *version);
        std::string v = version->get<std::string>();
        if (v.rfind("2.", 0) != 0)
            bad("", format("glTF version '%s' is not supported (need 2.x)", v.c_str()));
        optString(*asset, "minVersion", "/asset");
        if (const json* mv = member(*asset, "minVersion"); mv && mv->get<std::string>() != "2.0")
            bad("", format("glTF minVersion '%s' is not supported (need 2.0)",
                           mv->get<std::string>().c_str()));
    }

    void checkNode(const json& n, const std::string& p) {
        optString(n, "name", p);
        optIndexArray(n, "children", p, "nodes");
        optIndex(n, "mesh", p, "meshes");
        optIndex(n, "camera", p, "cameras");
        optIndex(n, "skin", p, "skins");
        optNumberArray(n, "matrix", p, 16);
        optNumberArray(n, "translation", p, 3);
        optNumberArray(n, "rotation", p, 4);
        optNumberArray(n, "scale", p, 3);
        optNumberArray(n, "weights", p, 0);
        checkExtensions(n, p);
        if (const json* ext = member(n, "extensions")) {
            if (const json* l = member(*ext, "KHR_lights_punctual"))
                requiredIndex(*l, "light", child(child(p, "extensions"), "KHR_lights_punctual"),
                              "lights");
        }
    }

    void checkMesh(const json& m, const std::string& p) {
        optString(m, "name", p);
        optNumberArray(m, "weights", p, 0);
        const json* prims = member(m, "primitives");
        if (!prims) bad(p, "missing required 'primitives'");
        if (!prims->is_array()) wrongType(child(p, "primitives"), "an array", *prims);
        if (prims->empty()) bad(child(p, "primitives"), "must not be empty");
        objectArray(m, "primitives", p, [&](const json& prim, const std::string& pp) {
            const json* attrs = member(prim, "attributes");
            if (!attrs) bad(pp, "missing required 'attributes'");
            if (!attrs->is_object()) wrongType(child(pp, "attributes"), "an object", *attrs);
            for (auto it = attrs->begin(); it != attrs->end(); ++it)
                checkIndexValue(*it, child(child(pp, "attributes"), it.key()), "accessors");
            optIndex(prim, "indices", pp, "accessors");
            optIndex(prim, "material", pp, "materials");
            if (const json* mode = member(prim, "mode")) {
                if (uintValue(*mode, child(pp, "mode")) > 6)
                    bad(child(pp, "mode"), format("invalid primitive mode %llu",
                                                  (unsigned long long)mode->get<uint64_t>()));
            }
            objectArray(prim, "targets", pp, [&](const json& t, const std::string& tp) {
                for (auto it = t.begin(); it != t.end(); ++it)
                    checkIndexValue(*it, child(tp, it.key()), "accessors");
            });
            checkExtensions(prim, pp);
        });
    }

    void checkAccessor(const json& a, const std::string& p) {
        optString(a, "name", p);
        optIndex(a, "bufferView", p, "bufferViews");
        optUint(a, "byteOffset", p);
        uint64_t type = requiredUint(a, "componentType", p);
        if (type != 5120 && type != 5121 && type != 5122 && type != 5123 && type != 5125 &&
            type != 5126)
            bad(child(p, "componentType"),
                format("invalid component type %llu", (unsigned long long)type));
        optBool(a, "normalized", p);
        requiredUint(a, "count", p, 1);
        const json* t = member(a, "type");
        if (!t) bad(p, "missing required 'type'");
        if (!t->is_string()) wrongType(child(p, "type"), "a string", *t);
        static const std::set<std::string> types = {"SCALAR", "VEC2", "VEC3", "VEC4",
                                                    "MAT2",   "MAT3", "MAT4"};
        if (!types.count(t->get<std::string>()))
            bad(child(p, "type"), "invalid accessor type '" + t->get<std::string>() + "'");
        optNumberArray(a, "min", p, 0);
        optNumberArray(a, "max", p, 0);
        optObject(a, "sparse", p, [&](const json& s, const std::string& sp) {
            requiredUint(s, "count", sp, 1);
            for (const char* part : {"indices", "values"}) {
                const json* o = member(s, part);
                if (!o) bad(sp, format("missing required '%s'", part));
                optObject(s, part, sp, [&](const json& io, const std::string& ip) {
                    requiredIndex(io, "bufferView", ip, "bufferViews");
                    optUint(io, "byteOffset", ip);
                    if (std::string_view(part) == "indices") {
                        uint64_t ct = requiredUint(io, "componentType", ip);
                        if (ct != 5121 && ct != 5123 && ct != 5125)
                            bad(child(ip, "componentType"), "sparse indices must be unsigned");
                    }
                });
            }
        });
    }

    void checkBufferView(const json& v, const std::string& p) {
        optString(v, "name", p);
        requiredIndex(v, "buffer", p, "buffers");
        optUint(v, "byteOffset", p);
        uint64_t length = requiredUint(v, "byteLength", p, 1);
        if (const json* s = member(v, "byteStride")) {
            uint64_t stride = uintValue(*s, child(p, "byteStride"));
            if (stride < 4 || stride > 252 || stride % 4 != 0)
                bad(child(p, "byteStride"),
                    format("invalid stride %llu (must be 4..252, a multiple of 4)",
                           (unsigned long long)stride));
        }
        optUint(v, "target", p);
        // The view must lie inside its buffer: tinygltf slices image data with it unchecked.
        uint64_t offset = member(v, "byteOffset") ? v["byteOffset"].get<uint64_t>() : 0;
        const json& buffer = root_["buffers"][v["buffer"].get<size_t>()];
        const json* bufferLength = buffer.is_object() ? member(buffer, "byteLength") : nullptr;
        if (bufferLength && bufferLength->is_number_unsigned()) {
            uint64_t size = bufferLength->get<uint64_t>();
            if (offset > size || length > size - offset)
                bad(p, format("byte range %llu+%llu exceeds buffer %zu (%llu bytes)",
                              (unsigned long long)offset, (unsigned long long)length,
                              v["buffer"].get<size_t>(), (unsigned long long)size));
        }
    }

    void checkTextureInfo(const json& obj, const char* key, const std::string& p) {
        optObject(obj, key, p, [&](const json& t, const std::string& tp) {
            requiredIndex(t, "index", tp, "textures");
            optUint(t, "texCoord", tp);
            optNumber(t, "scale", tp);
            optNumber(t, "strength", tp);
            checkExtensions(t, tp);
            if (const json* ext = member(t, "extensions"))
                optObject(*ext, "KHR_texture_transform", child(tp, "extensions"),
                          [&](const json& tt, const std::string& ttp) {
                              optNumberArray(tt, "offset", ttp, 2);
                              optNumberArray(tt, "scale", ttp, 2);
                              optNumber(tt, "rotation", ttp);
                              optUint(tt, "texCoord", ttp);
                          });
        });
    }

    // The material extensions gltf_materials.cpp reads: numbers, colours and texture infos.
    void checkMaterialExtensions(const json& ext, const std::string& p) {
        struct Field {
            const char* key;
            size_t size; // 0: a number; otherwise an array of that many numbers
        };
        struct Known {
            const char* name;
            std::vector<Field> numbers;
            std::vector<const char*> textures;
        };
        static const Known known[] = {
            {"KHR_materials_emissive_strength", {{"emissiveStrength", 0}}, {}},
            {"KHR_materials_unlit", {}, {}},
            {"KHR_materials_pbrSpecularGlossiness",
             {{"diffuseFactor", 4}, {"specularFactor", 3}, {"glossinessFactor", 0}},
             {"diffuseTexture", "specularGlossinessTexture"}},
            {"KHR_materials_clearcoat",
             {{"clearcoatFactor", 0}, {"clearcoatRoughnessFactor", 0}},
             {"clearcoatTexture", "clearcoatRoughnessTexture", "clearcoatNormalTexture"}},
            {"KHR_materials_ior", {{"ior", 0}}, {}},
            {"KHR_materials_specular",
             {{"specularFactor", 0}, {"specularColorFactor", 3}},
             {"specularTexture", "specularColorTexture"}},
            {"KHR_materials_sheen",
             {{"sheenColorFactor", 3}, {"sheenRoughnessFactor", 0}},
             {"sheenColorTexture", "sheenRoughnessTexture"}},
            {"KHR_materials_transmission", {{"transmissionFactor", 0}}, {"transmissionTexture"}},
            {"KHR_materials_volume",
             {{"thicknessFactor", 0}, {"attenuationDistance", 0}, {"attenuationColor", 3}},
             {"thicknessTexture"}},
        };
        for (const Known& k : known) {
            const json* e = member(ext, k.name);
            if (!e) continue;
            std::string ep = child(p, k.name);
            for (const Field& f : k.numbers) {
                if (f.size == 0)
                    optNumber(*e, f.key, ep, 0.0);
                else
                    optNumberArray(*e, f.key, ep, f.size);
            }
            for (const char* t : k.textures) checkTextureInfo(*e, t, ep);
        }
    }

    void checkMaterial(const json& m, const std::string& p) {
        optString(m, "name", p);
        optObject(m, "pbrMetallicRoughness", p, [&](const json& pbr, const std::string& pp) {
            optNumberArray(pbr, "baseColorFactor", pp, 4);
            optNumber(pbr, "metallicFactor", pp);
            optNumber(pbr, "roughnessFactor", pp);
            checkTextureInfo(pbr, "baseColorTexture", pp);
            checkTextureInfo(pbr, "metallicRoughnessTexture", pp);
            checkExtensions(pbr, pp);
        });
        checkTextureInfo(m, "normalTexture", p);
        checkTextureInfo(m, "occlusionTexture", p);
        checkTextureInfo(m, "emissiveTexture", p);
        optNumberArray(m, "emissiveFactor", p, 3);
        optString(m, "alphaMode", p);
        if (const json* mode = member(m, "alphaMode")) {
            std::string s = mode->get<std::string>();
            if (s != "OPAQUE" && s != "MASK" && s != "BLEND")
                bad(child(p, "alphaMode"), "must be OPAQUE, MASK or BLEND (got '" + s + "')");
        }
        optNumber(m, "alphaCutoff", p, 0.0);
        optBool(m, "doubleSided", p);
        checkExtensions(m, p);
        if (const json* ext = member(m, "extensions"))
            checkMaterialExtensions(*ext, child(p, "extensions"));
    }

    void checkImage(const json& i, const std::string& p) {
        optString(i, "name", p);
        optString(i, "uri", p);
        optString(i, "mimeType", p);
        optIndex(i, "bufferView", p, "bufferViews");
        if (!member(i, "uri") && !member(i, "bufferView"))
            bad(p, "image has neither 'uri' nor 'bufferView'");
    }

    void checkCamera(const json& c, const std::string& p) {
        optString(c, "name", p);
        const json* type = member(c, "type");
        if (!type) bad(p, "missing required 'type'");
        if (!type->is_string()) wrongType(child(p, "type"), "a string", *type);
        optObject(c, "perspective", p, [&](const json& persp, const std::string& pp) {
            if (!member(persp, "yfov") || !member(persp, "znear"))
                bad(pp, "perspective camera needs 'yfov' and 'znear'");
            optNumber(persp, "yfov", pp, 1e-6);
            optNumber(persp, "znear", pp, 1e-9);
            optNumber(persp, "zfar", pp, 0.0);
            optNumber(persp, "aspectRatio", pp, 0.0);
        });
        optObject(c, "orthographic", p, [&](const json& o, const std::string& op) {
            for (const char* key : {"xmag", "ymag", "znear", "zfar"}) optNumber(o, key, op);
        });
        if (type->get<std::string>() == "perspective" && !member(c, "perspective"))
            bad(p, "perspective camera without 'perspective' object");
    }

    void checkLight(const json& l, const std::string& p) {
        optString(l, "name", p);
        const json* type = member(l, "type");
        if (!type) bad(p, "missing required 'type'");
        if (!type->is_string()) wrongType(child(p, "type"), "a string", *type);
        std::string t = type->get<std::string>();
        if (t != "directional" && t != "point" && t != "spot")
            bad(child(p, "type"), "must be directional, point or spot (got '" + t + "')");
        optNumberArray(l, "color", p, 3);
        optNumber(l, "intensity", p, 0.0);
        optNumber(l, "range", p, 0.0);
        optObject(l, "spot", p, [&](const json& s, const std::string& sp) {
            optNumber(s, "innerConeAngle", sp, 0.0);
            optNumber(s, "outerConeAngle", sp, 0.0);
        });
    }
};

// --- Gate 2: tinygltf ----------------------------------------------------------------------

// Decodes every image to RGBA8. A broken image is reported and left empty (the material then
// renders without that texture) instead of failing the whole scene.
bool decodeImageToRgba8(tinygltf::Image* image, const int index, std::string*, std::string* warn,
                        int, int, const unsigned char* bytes, int size, void*) {
    auto reject = [&](const std::string& why) {
        if (warn) *warn += format("image %d could not be decoded (%s)\n", index, why.c_str());
        image->image.clear();
        image->width = image->height = 0;
        return true;
    };
    int w = 0, h = 0, channels = 0;
    if (!stbi_info_from_memory(bytes, size, &w, &h, &channels))
        return reject(stbi_failure_reason() ? stbi_failure_reason() : "unknown format");
    if (w <= 0 || h <= 0 || uint64_t(w) * uint64_t(h) > kMaxImagePixels)
        return reject(format("%dx%d is too large", w, h));
    stbi_uc* pixels = stbi_load_from_memory(bytes, size, &w, &h, &channels, 4);
    if (!pixels) return reject(stbi_failure_reason() ? stbi_failure_reason() : "decode failed");
    image->width = w;
    image->height = h;
    image->component = 4;
    image->bits = 8;
    image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    image->image.assign(pixels, pixels + size_t(w) * size_t(h) * 4);
    stbi_image_free(pixels);
    return true;
}

// Where external files may be read from (the fs callbacks' user data).
struct FileAccess {
    std::string modelFolder;
    bool allowExternal = false;
    bool permits(const std::string& path) const {
        return allowExternal || pathInsideFolder(path, modelFolder);
    }
};

// tinygltf also looks for a relative URI in the working directory; outside the model's folder
// a file does not exist for it (the URI check above gives the clear error first).
bool fsFileExists(const std::string& path, void* access) {
    if (!static_cast<const FileAccess*>(access)->permits(path)) return false;
    std::error_code ec;
    return std::filesystem::is_regular_file(path, ec);
}
std::string fsExpandPath(const std::string& path, void*) {
    return path;
}
bool fsReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                     void* access) {
    if (!static_cast<const FileAccess*>(access)->permits(path)) {
        if (err) *err += path + " is outside the model's folder";
        return false;
    }
    std::error_code ec;
    uint64_t size = std::filesystem::file_size(path, ec);
    if (ec || size > kMaxFileBytes) {
        if (err) *err += ec ? "cannot read " + path : path + " is larger than the size limit";
        return false;
    }
    std::ifstream in(path, std::ios::binary);
    out->resize(size);
    if (!in ||
        (size > 0 && !in.read(reinterpret_cast<char*>(out->data()), std::streamsize(size)))) {
        if (err) *err += "cannot read " + path;
        return false;
    }
    return true;
}
bool fsWriteWholeFile(std::string*, const std::string&, const std::vector<unsigned char>&, void*) {
    return false;
}

// --- Gate 3: conversion --------------------------------------------------------------------

size_t componentSize(int componentType) {
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return 4;
    default:
        return 0;
    }
}

const char* typeName(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR:
        return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
        return "VEC2";
    case TINYGLTF_TYPE_VEC3:
        return "VEC3";
    case TINYGLTF_TYPE_VEC4:
        return "VEC4";
    default:
        return "MATRIX";
    }
}

float componentAsFloat(const uint8_t* p, int componentType, bool normalized) {
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float f;
        std::memcpy(&f, p, 4);
        return f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return normalized ? *p / 255.0f : float(*p);
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        float v = float(int8_t(*p));
        return normalized ? std::max(v / 127.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? v / 65535.0f : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? std::max(v / 32767.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return float(v);
    }
    default:
        return 0.0f;
    }
}

uint32_t componentAsUint(const uint8_t* p, int componentType) {
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return *p;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return v;
    }
    default:
        return 0;
    }
}

bool finite3(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
bool finiteMatrix(const glm::mat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

class GltfConverter {
public:
    // `skinning`: skinned meshes are posed by their joints (with --time); otherwise drawn in
    // their bind pose.
    // `addDefaultSun`: a file without a directional light gets "auto-sun" (--sun auto).
    GltfConverter(const tinygltf::Model& model, const std::string& input, Scene& scene,
                  bool skinning, bool addDefaultSun)
        : model_(model), input_(input), scene_(scene), skinning_(skinning),
          addDefaultSun_(addDefaultSun) {}

    void run() {
        for (size_t i = 0; i < model_.accessors.size(); ++i) validateAccessor(int(i));
        for (size_t i = 0; i < model_.materials.size(); ++i)
            scene_.materials.push_back(convertMaterial(int(i)));
        meshParts_.resize(model_.meshes.size());
        pointLineParts_.resize(model_.meshes.size());
        meshConverted_.assign(model_.meshes.size(), false);
        traverseNodes();
        if (scene_.triangleCount() == 0 && scene_.pointLines.empty()) {
            std::string why = "no triangles to render";
            if (skippedPrimitives_ > 0)
                why += format(" (%u primitive(s) skipped: %s)", skippedPrimitives_,
                              skipReasons_.c_str());
            fail(input_, why);
        }
        finishCamerasAndLights();
    }

private:
    struct AccessorData {
        const uint8_t* base = nullptr; // null: all zeros (no bufferView)
        size_t stride = 0;
        size_t count = 0;
        int components = 0;
        int componentType = 0;
        bool normalized = false;
    };

    const tinygltf::Model& model_;
    const std::string& input_;
    Scene& scene_;
    std::vector<std::vector<uint32_t>> meshParts_;
    std::vector<std::vector<PointLineSet>> pointLineParts_; // per glTF mesh, object space
    std::vector<bool> meshConverted_;
    std::map<uint32_t, uint32_t> mirroredMesh_;        // mesh -> copy with reversed winding
    std::map<std::pair<int, bool>, int32_t> textures_; // (image, sRGB) -> scene texture
    int32_t defaultMaterial_ = -1;
    uint32_t skippedPrimitives_ = 0;
    std::string skipReasons_;
    std::set<std::string> warnedOnce_;
    std::vector<bool> cameraZfarGiven_;
    bool skinning_ = false;
    bool addDefaultSun_ = true;
    std::vector<glm::mat4> worldOf_; // every node's world transform (identity if unreached)

    [[noreturn]] void error(const std::string& reason) { fail(input_, reason); }
    void warn(const std::string& what) { SHADEL_WARN("%s: %s", input_.c_str(), what.c_str()); }
    void warnOnce(const std::string& what) {
        if (warnedOnce_.insert(what).second) warn(what);
    }
    void noteSkip(const std::string& reason) {
        ++skippedPrimitives_;
        if (skipReasons_.find(reason) == std::string::npos)
            skipReasons_ += (skipReasons_.empty() ? "" : ", ") + reason;
    }

    // Resolves an accessor to bytes, checking that every element lies inside its buffer view
    // and buffer. Sparse accessors are checked when read.
    AccessorData resolveAccessor(int index) {
        const tinygltf::Accessor& acc = model_.accessors[size_t(index)];
        AccessorData out;
        out.count = acc.count;
        out.components = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
        out.componentType = acc.componentType;
        out.normalized = acc.normalized;
        if (acc.count == 0 || acc.count > kMaxAccessorCount)
            error(format("accessor %d count %zu is out of range (limit %llu)", index, acc.count,
                         (unsigned long long)kMaxAccessorCount));
        size_t elementSize = componentSize(acc.componentType) * size_t(out.components);
        if (elementSize == 0) error(format("accessor %d has an invalid component type", index));
        if (acc.bufferView < 0) return out; // zeros, maybe with sparse values on top
        const tinygltf::BufferView& view = model_.bufferViews[size_t(acc.bufferView)];
        const tinygltf::Buffer& buffer = model_.buffers[size_t(view.buffer)];
        if (view.byteOffset > buffer.data.size() ||
            view.byteLength > buffer.data.size() - view.byteOffset)
            error(format("buffer view %d (bytes %zu+%zu) exceeds buffer %d (%zu bytes)",
                         acc.bufferView, view.byteOffset, view.byteLength, view.buffer,
                         buffer.data.size()));
        out.stride = view.byteStride ? view.byteStride : elementSize;
        if (out.stride < elementSize)
            error(format("accessor %d: stride %zu is smaller than its %zu-byte elements", index,
                         out.stride, elementSize));
        uint64_t needed =
            uint64_t(acc.byteOffset) + uint64_t(out.stride) * (acc.count - 1) + elementSize;
        if (acc.byteOffset > view.byteLength || needed > view.byteLength)
            error(format("accessor %d (%zu x %s at offset %zu) exceeds buffer view %d (%zu bytes)",
                         index, acc.count, typeName(acc.type), acc.byteOffset, acc.bufferView,
                         view.byteLength));
        out.base = buffer.data.data() + view.byteOffset + acc.byteOffset;
        return out;
    }

    void validateAccessor(int index) { resolveAccessor(index); }

    // Reads an accessor as floats, `components` per element (after checking the type).
    std::vector<float> readFloats(int index, int components, const char* semantic) {
        const tinygltf::Accessor& acc = model_.accessors[size_t(index)];
        AccessorData a = resolveAccessor(index);
        if (a.components != components)
            error(format("accessor %d (%s) is %s, expected %s", index, semantic, typeName(acc.type),
                         typeName(components == 2   ? TINYGLTF_TYPE_VEC2
                                  : components == 3 ? TINYGLTF_TYPE_VEC3
                                                    : TINYGLTF_TYPE_VEC4)));
        if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            error(format("accessor %d (%s) has unsigned int components, not allowed for %s", index,
                         semantic, semantic));
        std::vector<float> out(a.count * size_t(components), 0.0f);
        size_t cs = componentSize(a.componentType);
        if (a.base) {
            for (size_t i = 0; i < a.count; ++i)
                for (int c = 0; c < components; ++c)
                    out[i * size_t(components) + size_t(c)] = componentAsFloat(
                        a.base + i * a.stride + size_t(c) * cs, a.componentType, a.normalized);
        }
        applySparse(index, [&](size_t element, const uint8_t* value) {
            for (int c = 0; c < components; ++c)
                out[element * size_t(components) + size_t(c)] =
                    componentAsFloat(value + size_t(c) * cs, a.componentType, a.normalized);
        });
        return out;
    }

    std::vector<uint32_t> readIndices(int index) {
        const tinygltf::Accessor& acc = model_.accessors[size_t(index)];
        AccessorData a = resolveAccessor(index);
        if (a.components != 1 || (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                                  a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                                  a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
            error(
                format("accessor %d (indices) must be an unsigned byte/short/int SCALAR (is %s of "
                       "component type %d)",
                       index, typeName(acc.type), acc.componentType));
        std::vector<uint32_t> out(a.count, 0);
        if (a.base)
            for (size_t i = 0; i < a.count; ++i)
                out[i] = componentAsUint(a.base + i * a.stride, a.componentType);
        applySparse(index, [&](size_t element, const uint8_t* value) {
            out[element] = componentAsUint(value, a.componentType);
        });
        return out;
    }

    // Calls apply(element, bytes of the value) for each sparse substitution, bounds-checked.
    template <typename F>
    void applySparse(int index, F&& apply) {
        const tinygltf::Accessor& acc = model_.accessors[size_t(index)];
        if (!acc.sparse.isSparse) return;
        const auto& sparse = acc.sparse;
        size_t count = size_t(sparse.count);
        if (sparse.count <= 0 || count > acc.count)
            error(format("accessor %d: sparse count %d out of range", index, sparse.count));
        size_t indexSize = componentSize(sparse.indices.componentType);
        size_t valueSize = componentSize(acc.componentType) *
                           size_t(tinygltf::GetNumComponentsInType(uint32_t(acc.type)));
        auto slice = [&](int viewIndex, int offset, size_t elementSize) -> const uint8_t* {
            if (viewIndex < 0 || size_t(viewIndex) >= model_.bufferViews.size() || offset < 0)
                error(format("accessor %d: invalid sparse buffer view", index));
            const tinygltf::BufferView& view = model_.bufferViews[size_t(viewIndex)];
            const tinygltf::Buffer& buffer = model_.buffers[size_t(view.buffer)];
            uint64_t end =
                uint64_t(view.byteOffset) + uint64_t(offset) + uint64_t(elementSize) * count;
            if (view.byteOffset > buffer.data.size() ||
                view.byteLength > buffer.data.size() - view.byteOffset ||
                end > uint64_t(view.byteOffset) + view.byteLength)
                error(format("accessor %d: sparse data exceeds buffer view %d", index, viewIndex));
            return buffer.data.data() + view.byteOffset + size_t(offset);
        };
        const uint8_t* indices =
            slice(sparse.indices.bufferView, sparse.indices.byteOffset, indexSize);
        const uint8_t* values =
            slice(sparse.values.bufferView, sparse.values.byteOffset, valueSize);
        for (size_t i = 0; i < count; ++i) {
            uint32_t element =
                componentAsUint(indices + i * indexSize, sparse.indices.componentType);
            if (element >= acc.count)
                error(format("accessor %d: sparse index %u out of range (count %zu)", index,
                             element, acc.count));
            apply(element, values + i * valueSize);
        }
    }

    int32_t texture(int textureIndex, bool srgb, const char* slot, int material) {
        if (textureIndex < 0) return kNoTexture;
        int source = model_.textures[size_t(textureIndex)].source;
        if (source < 0) {
            warn(format(
                "texture %d has no supported image source; material %d renders without its %s "
                "texture",
                textureIndex, material, slot));
            return kNoTexture;
        }
        const tinygltf::Image& image = model_.images[size_t(source)];
        if (image.image.empty() || image.width <= 0 || image.height <= 0) {
            warn(
                format("image %d%s could not be loaded; material %d renders without its %s texture",
                       source, image.uri.empty() ? "" : (" ('" + image.uri + "')").c_str(),
                       material, slot));
            return kNoTexture;
        }
        auto key = std::make_pair(source, srgb);
        if (auto it = textures_.find(key); it != textures_.end()) return it->second;
        Texture tex;
        tex.name = !image.name.empty()  ? image.name
                   : !image.uri.empty() ? image.uri
                                        : format("image %d", source);
        tex.width = uint32_t(image.width);
        tex.height = uint32_t(image.height);
        tex.rgba8 = image.image;
        tex.srgb = srgb;
        int32_t index = int32_t(scene_.textures.size());
        scene_.textures.push_back(std::move(tex));
        textures_[key] = index;
        return index;
    }

    // Additiveness of a BLEND material (render/oit): glTF has no such property, so an explicit
    // `extras.additiveness` in [0, 1] wins; otherwise a material that boosts its emission with
    // KHR_materials_emissive_strength is taken for a glow: additiveness 1 - 1/strength (0 at
    // strength 1, 0.5 at 2, 0.9 at 10). Other materials stay alpha-blended.
    static float blendAdditiveness(const tinygltf::Material& m, float emissiveStrength) {
        if (m.alphaMode != "BLEND") return 0.0f;
        if (m.extras.IsObject() && m.extras.Has("additiveness")) {
            const tinygltf::Value& a = m.extras.Get("additiveness");
            if (a.IsNumber()) {
                double v = a.GetNumberAsDouble();
                if (std::isfinite(v)) return std::clamp(float(v), 0.0f, 1.0f);
            }
        }
        if (emissiveStrength > 1.0f && std::isfinite(emissiveStrength))
            return std::clamp(1.0f - 1.0f / emissiveStrength, 0.0f, 1.0f);
        return 0.0f;
    }

    Material convertMaterial(int index) {
        const tinygltf::Material& m = model_.materials[size_t(index)];
        const auto& pbr = m.pbrMetallicRoughness;
        Material out;
        out.name = m.name.empty() ? format("material %d", index) : m.name;
        if (pbr.baseColorFactor.size() == 4)
            out.baseColorFactor =
                glm::vec4(float(pbr.baseColorFactor[0]), float(pbr.baseColorFactor[1]),
                          float(pbr.baseColorFactor[2]), float(pbr.baseColorFactor[3]));
        out.metallicFactor = std::clamp(float(pbr.metallicFactor), 0.0f, 1.0f);
        out.roughnessFactor = std::clamp(float(pbr.roughnessFactor), 0.0f, 1.0f);
        if (m.emissiveFactor.size() == 3)
            out.emissiveFactor = glm::vec3(float(m.emissiveFactor[0]), float(m.emissiveFactor[1]),
                                           float(m.emissiveFactor[2]));
        // Read here for the additiveness of blended materials; gltf_materials applies it to the
        // emissive factor with the other material extensions.
        float emissiveStrength = 1.0f;
        if (auto it = m.extensions.find("KHR_materials_emissive_strength");
            it != m.extensions.end()) {
            const tinygltf::Value& strength = it->second.Get("emissiveStrength");
            if (strength.IsNumber()) emissiveStrength = float(strength.GetNumberAsDouble());
        }
        out.normalScale = float(m.normalTexture.scale);
        out.occlusionStrength = std::clamp(float(m.occlusionTexture.strength), 0.0f, 1.0f);
        out.alphaCutoff = float(m.alphaCutoff);
        out.alphaMode = m.alphaMode == "MASK"    ? AlphaMode::Mask
                        : m.alphaMode == "BLEND" ? AlphaMode::Blend
                                                 : AlphaMode::Opaque;
        out.doubleSided = m.doubleSided;
        out.additiveness = blendAdditiveness(m, emissiveStrength);
        out.baseColorTexture = texture(pbr.baseColorTexture.index, true, "base colour", index);
        out.metallicRoughnessTexture =
            texture(pbr.metallicRoughnessTexture.index, false, "metal-roughness", index);
        out.normalTexture = texture(m.normalTexture.index, false, "normal", index);
        out.occlusionTexture = texture(m.occlusionTexture.index, false, "occlusion", index);
        out.emissiveTexture = texture(m.emissiveTexture.index, true, "emissive", index);
        MaterialTextures textures;
        textures.resolve = [&](int t, bool srgb, const char* slot) {
            return texture(t, srgb, slot, index);
        };
        textures.sampler = [&](int t) { return gltfTextureSampler(model_, t); };
        textures.glossinessToRoughness = [&](int t, float glossinessFactor) {
            return glossinessToRoughness(t, glossinessFactor, index);
        };
        textures.warn = [&](const std::string& what) { warnOnce(what); };
        applyMaterialExtensions(m, index, out, textures);
        return out;
    }

    // A metallic-roughness texture (G = 1 - alpha x glossinessFactor, B = 0) from a
    // specularGlossinessTexture (glossiness in alpha).
    int32_t glossinessToRoughness(int textureIndex, float glossinessFactor, int material) {
        int32_t source = texture(textureIndex, false, "specular-glossiness", material);
        if (source == kNoTexture) return kNoTexture;
        Texture tex = scene_.textures[size_t(source)];
        tex.name += " (roughness from glossiness)";
        for (size_t i = 0; i + 3 < tex.rgba8.size(); i += 4) {
            float gloss = tex.rgba8[i + 3] / 255.0f * glossinessFactor;
            tex.rgba8[i] = 0;
            tex.rgba8[i + 1] = uint8_t(std::lround((1.0f - gloss) * 255.0f));
            tex.rgba8[i + 2] = 0;
            tex.rgba8[i + 3] = 255;
        }
        scene_.textures.push_back(std::move(tex));
        return int32_t(scene_.textures.size() - 1);
    }

    uint32_t defaultMaterial() {
        if (defaultMaterial_ < 0) {
            // glTF's default material: white, fully metallic, fully rough.
            Material m;
            m.name = "default";
            m.metallicFactor = 1.0f;
            m.roughnessFactor = 1.0f;
            defaultMaterial_ = int32_t(scene_.materials.size());
            scene_.materials.push_back(m);
        }
        return uint32_t(defaultMaterial_);
    }

    // Triangle list from a primitive's index list and mode; strips and fans are unrolled (their
    // degenerate "restart" triangles dropped).
    std::vector<uint32_t> triangulate(const std::vector<uint32_t>& idx, int mode,
                                      const std::string& where) {
        std::vector<uint32_t> tris;
        auto add = [&](uint32_t a, uint32_t b, uint32_t c, bool dropDegenerate) {
            if (dropDegenerate && (a == b || b == c || a == c)) return;
            tris.insert(tris.end(), {a, b, c});
        };
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            if (idx.size() % 3 != 0)
                warn(format("%s: %zu indices is not a multiple of 3; the last %zu ignored",
                            where.c_str(), idx.size(), idx.size() % 3));
            for (size_t i = 0; i + 2 < idx.size(); i += 3)
                add(idx[i], idx[i + 1], idx[i + 2], false);
        } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
            for (size_t i = 0; i + 2 < idx.size(); ++i) {
                // Every other triangle of a strip is reversed to keep the winding consistent.
                if (i % 2 == 0)
                    add(idx[i], idx[i + 1], idx[i + 2], true);
                else
                    add(idx[i + 1], idx[i], idx[i + 2], true);
            }
        } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
            for (size_t i = 1; i + 1 < idx.size(); ++i) add(idx[i], idx[i + 1], idx[0], true);
        }
        return tris;
    }

    // `weights`: the morph target weights of the node that first uses the mesh (or the mesh's).
    void convertMesh(int meshIndex, const std::vector<double>& nodeWeights) {
        meshConverted_[size_t(meshIndex)] = true;
        const tinygltf::Mesh& gm = model_.meshes[size_t(meshIndex)];
        const std::vector<double>& weights = nodeWeights.empty() ? gm.weights : nodeWeights;
        for (size_t p = 0; p < gm.primitives.size(); ++p) {
            std::string where = format("mesh %d primitive %zu", meshIndex, p);
            if (isPointsOrLines(gm.primitives[p])) { // drawn forward (render/points_lines)
                PointLineSet set = convertPointsOrLines(gm.primitives[p], where, weights);
                set.name =
                    (gm.name.empty() ? format("mesh%d", meshIndex) : gm.name) + format("/%zu", p);
                if (!set.vertices.empty()) pointLineParts_[size_t(meshIndex)].push_back(set);
                continue;
            }
            std::optional<Mesh> mesh = convertPrimitive(gm.primitives[p], where, weights);
            if (!mesh) continue;
            mesh->name = (gm.name.empty() ? format("mesh%d", meshIndex) : gm.name) +
                         (gm.primitives.size() > 1 ? format("/%zu", p) : std::string());
            for (Mesh& part : splitMesh(std::move(*mesh))) {
                meshParts_[size_t(meshIndex)].push_back(uint32_t(scene_.meshes.size()));
                scene_.meshes.push_back(std::move(part));
            }
        }
    }

    static bool isPointsOrLines(const tinygltf::Primitive& prim) {
        return prim.mode == TINYGLTF_MODE_POINTS || prim.mode == TINYGLTF_MODE_LINE ||
               prim.mode == TINYGLTF_MODE_LINE_LOOP || prim.mode == TINYGLTF_MODE_LINE_STRIP;
    }

    // Points: one per vertex (or per index); lines, strips and loops: a list of segments.
    // Positions (with morph targets), COLOR_0 and the material; no normals (drawn unlit).
    PointLineSet convertPointsOrLines(const tinygltf::Primitive& prim, const std::string& where,
                                      const std::vector<double>& weights) {
        auto it = prim.attributes.find("POSITION");
        if (it == prim.attributes.end()) error(where + " has no POSITION attribute");
        std::vector<float> positions = readFloats(it->second, 3, "POSITION");
        size_t vertexCount = positions.size() / 3;
        Mesh points; // positions through the same morph code as triangles
        points.vertices.resize(vertexCount);
        for (size_t v = 0; v < vertexCount; ++v) {
            glm::vec3 p = glm::make_vec3(&positions[v * 3]);
            if (!finite3(p))
                error(format("accessor %d (POSITION) element %zu is not finite", it->second, v));
            points.vertices[v].position = p;
        }
        std::vector<float> noNormals;
        applyMorphTargets(prim, weights, vertexCount, points, noNormals);
        std::vector<glm::vec4> colors;
        if (auto c = prim.attributes.find("COLOR_0"); c != prim.attributes.end()) {
            int components = model_.accessors[size_t(c->second)].type == TINYGLTF_TYPE_VEC3 ? 3 : 4;
            std::vector<float> data = readFloats(c->second, components, "COLOR_0");
            if (data.size() / size_t(components) != vertexCount)
                error(format("%s: COLOR_0 has %zu elements but POSITION has %zu", where.c_str(),
                             data.size() / size_t(components), vertexCount));
            for (size_t v = 0; v < vertexCount; ++v)
                colors.push_back(glm::vec4(
                    data[v * size_t(components)], data[v * size_t(components) + 1],
                    data[v * size_t(components) + 2], components == 4 ? data[v * 4 + 3] : 1.0f));
        }
        std::vector<uint32_t> idx;
        if (prim.indices >= 0) {
            idx = readIndices(prim.indices);
            for (uint32_t i : idx)
                if (i >= vertexCount)
                    error(format("accessor %d index %u out of range (vertex count %zu)",
                                 prim.indices, i, vertexCount));
        } else {
            idx.resize(vertexCount);
            for (size_t i = 0; i < vertexCount; ++i) idx[i] = uint32_t(i);
        }
        std::vector<uint32_t> order; // vertices drawn, pairs for lines
        if (prim.mode == TINYGLTF_MODE_POINTS || prim.mode == TINYGLTF_MODE_LINE) {
            order = idx;
            if (prim.mode == TINYGLTF_MODE_LINE) order.resize(order.size() / 2 * 2);
        } else {
            for (size_t i = 0; i + 1 < idx.size(); ++i)
                order.push_back(idx[i]), order.push_back(idx[i + 1]);
            if (prim.mode == TINYGLTF_MODE_LINE_LOOP && idx.size() > 2)
                order.push_back(idx.back()), order.push_back(idx.front());
        }
        PointLineSet set;
        set.lines = prim.mode != TINYGLTF_MODE_POINTS;
        set.material = prim.material >= 0 ? uint32_t(prim.material) : defaultMaterial();
        for (uint32_t i : order) {
            set.vertices.push_back(points.vertices[i]);
            if (!colors.empty()) set.colors.push_back(colors[i]);
        }
        return set;
    }

    std::optional<Mesh> convertPrimitive(const tinygltf::Primitive& prim, const std::string& where,
                                         const std::vector<double>& weights) {
        int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            mode != TINYGLTF_MODE_TRIANGLE_FAN) {
            warn(where + ": points/lines are not rendered; skipped");
            noteSkip("points/lines");
            return std::nullopt;
        }
        // An optional KHR_draco_mesh_compression (ignored, warned once for the file) leaves the
        // primitive's uncompressed accessors as the fallback; a required one was refused.
        auto attribute = [&](const char* name) {
            auto it = prim.attributes.find(name);
            return it == prim.attributes.end() ? -1 : it->second;
        };
        int positionAccessor = attribute("POSITION");
        if (positionAccessor < 0) error(where + " has no POSITION attribute");
        std::vector<float> positions = readFloats(positionAccessor, 3, "POSITION");
        size_t vertexCount = positions.size() / 3;
        Mesh mesh;
        mesh.vertices.resize(vertexCount);
        for (size_t v = 0; v < vertexCount; ++v) {
            glm::vec3 p = glm::make_vec3(&positions[v * 3]);
            if (!finite3(p))
                error(format("accessor %d (POSITION) element %zu is not finite", positionAccessor,
                             v));
            mesh.vertices[v].position = p;
        }
        auto readAttribute = [&](const char* name, int components) -> std::vector<float> {
            int accessor = attribute(name);
            if (accessor < 0) return {};
            std::vector<float> data = readFloats(accessor, components, name);
            if (data.size() / size_t(components) != vertexCount)
                error(format("accessor %d (%s) has %zu elements but POSITION has %zu", accessor,
                             name, data.size() / size_t(components), vertexCount));
            return data;
        };
        std::vector<float> normals = readAttribute("NORMAL", 3);
        std::vector<float> tangents = readAttribute("TANGENT", 4);
        applyMorphTargets(prim, weights, vertexCount, mesh, normals);
        // Two UV sets (float, or normalized unsigned byte / short: readFloats scales them); a
        // mesh without a second one reads the first wherever a material asks for it.
        std::vector<float> uvs = readAttribute("TEXCOORD_0", 2);
        std::vector<float> uvs1 = readAttribute("TEXCOORD_1", 2);
        for (size_t v = 0; v < vertexCount; ++v) {
            Vertex& vert = mesh.vertices[v];
            if (!normals.empty()) vert.normal = glm::make_vec3(&normals[v * 3]);
            if (!tangents.empty()) vert.tangent = glm::make_vec4(&tangents[v * 4]);
            if (!uvs.empty()) vert.uv0 = glm::make_vec2(&uvs[v * 2]);
            vert.uv1 = uvs1.empty() ? vert.uv0 : glm::make_vec2(&uvs1[v * 2]);
        }

        std::vector<uint32_t> indices;
        if (prim.indices >= 0) {
            indices = readIndices(prim.indices);
            for (uint32_t i : indices)
                if (i >= vertexCount)
                    error(format("accessor %d index %u out of range (vertex count %zu)",
                                 prim.indices, i, vertexCount));
        } else {
            indices.resize(vertexCount);
            for (size_t i = 0; i < vertexCount; ++i) indices[i] = uint32_t(i);
        }
        mesh.indices = triangulate(indices, mode, where);
        if (mesh.indices.empty()) {
            warn(where + " has no triangles; skipped");
            noteSkip("no triangles");
            return std::nullopt;
        }
        mesh.material = prim.material >= 0 ? uint32_t(prim.material) : defaultMaterial();
        if (uvs1.empty() && mesh.material < scene_.materials.size()) {
            const uint8_t* sets = scene_.materials[mesh.material].texCoords;
            if (std::find(sets, sets + kTextureSlotCount, 1) != sets + kTextureSlotCount)
                warnOnce(format("%s: material '%s' reads TEXCOORD_1, which the primitive lacks; "
                                "it reads TEXCOORD_0",
                                where.c_str(), scene_.materials[mesh.material].name.c_str()));
        }

        if (normals.empty()) computeSmoothNormals(mesh);
        if (tangents.empty()) {
            // Tangents from the UV gradients need valid normals first.
            sanitizeNormalsAndTangents(mesh);
            // Along the normal map's UV set (glTF: tangents follow the normal texture's).
            int normalSet =
                mesh.material < scene_.materials.size()
                    ? scene_.materials[mesh.material].texCoords[uint32_t(TextureSlot::Normal)]
                    : 0;
            computeTangents(mesh, normalSet);
        }
        if (uint32_t repaired = sanitizeNormalsAndTangents(mesh); repaired > 0)
            warn(format("%s: %u vertices had invalid normals/tangents/UVs; repaired", where.c_str(),
                        repaired));
        computeBounds(mesh);
        return mesh;
    }

    // Adds sum(weight x target) to positions and normals (glTF morph targets hold deltas).
    void applyMorphTargets(const tinygltf::Primitive& prim, const std::vector<double>& weights,
                           size_t vertexCount, Mesh& mesh, std::vector<float>& normals) {
        for (size_t t = 0; t < prim.targets.size() && t < weights.size(); ++t) {
            float w = float(weights[t]);
            if (w == 0.0f || !std::isfinite(w)) continue;
            for (const auto& [name, accessor] : prim.targets[t]) {
                bool position = name == "POSITION";
                if (!position && (name != "NORMAL" || normals.empty())) continue;
                std::vector<float> delta = readFloats(accessor, 3, name.c_str());
                if (delta.size() != vertexCount * 3)
                    error(format("morph target %zu %s has %zu elements but POSITION has %zu", t,
                                 name.c_str(), delta.size() / 3, vertexCount));
                for (size_t v = 0; v < vertexCount; ++v) {
                    glm::vec3 d = glm::make_vec3(&delta[v * 3]) * w;
                    if (position) {
                        mesh.vertices[v].position += d;
                        if (!finite3(mesh.vertices[v].position))
                            error(format("morph target %zu moves vertex %zu to a non-finite "
                                         "position",
                                         t, v));
                    } else {
                        for (int c = 0; c < 3; ++c) normals[v * 3 + size_t(c)] += d[c];
                    }
                }
            }
        }
    }

    glm::mat4 localMatrix(const tinygltf::Node& node, int index) {
        glm::mat4 m(1.0f);
        if (node.matrix.size() == 16) {
            for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = float(node.matrix[size_t(i)]);
        } else {
            glm::vec3 t(0.0f), s(1.0f);
            glm::quat r(1, 0, 0, 0);
            if (node.translation.size() == 3)
                t = {float(node.translation[0]), float(node.translation[1]),
                     float(node.translation[2])};
            if (node.scale.size() == 3)
                s = {float(node.scale[0]), float(node.scale[1]), float(node.scale[2])};
            if (node.rotation.size() == 4) {
                // glTF stores x, y, z, w; glm's constructor takes w first.
                r = glm::quat(float(node.rotation[3]), float(node.rotation[0]),
                              float(node.rotation[1]), float(node.rotation[2]));
                float len = glm::length(r);
                if (!(len > 1e-6f) || !std::isfinite(len))
                    error(format("node %d rotation is not a valid quaternion", index));
                r /= len;
            }
            m = glm::translate(glm::mat4(1.0f), t) * glm::mat4_cast(r) *
                glm::scale(glm::mat4(1.0f), s);
        }
        if (!finiteMatrix(m)) error(format("node %d has a non-finite transform", index));
        return m;
    }

    uint32_t mirroredCopy(uint32_t mesh) {
        if (auto it = mirroredMesh_.find(mesh); it != mirroredMesh_.end()) return it->second;
        Mesh copy = scene_.meshes[mesh];
        copy.name += " (mirrored)";
        for (size_t t = 0; t + 2 < copy.indices.size(); t += 3)
            std::swap(copy.indices[t + 1], copy.indices[t + 2]);
        uint32_t index = uint32_t(scene_.meshes.size());
        scene_.meshes.push_back(std::move(copy));
        mirroredMesh_[mesh] = index;
        return index;
    }

    void addNodeContent(const tinygltf::Node& node, int index, const glm::mat4& world) {
        std::string nodeName = node.name.empty() ? format("node%d", index) : node.name;
        if (node.skin >= 0 && node.mesh >= 0 && skinning_) {
            addSkinnedMesh(node, index, nodeName);
        } else if (node.mesh >= 0) {
            if (node.skin >= 0)
                warnOnce("skinned meshes are drawn in their bind pose without --time");
            if (!meshConverted_[size_t(node.mesh)]) convertMesh(node.mesh, node.weights);
            // A mirroring transform turns CCW into CW: give those instances a mesh with the
            // winding reversed so front faces stay front faces.
            bool mirrored = glm::determinant(glm::mat3(world)) < 0.0f;
            const auto& parts = meshParts_[size_t(node.mesh)];
            for (size_t p = 0; p < parts.size(); ++p) {
                Instance inst;
                inst.name = parts.size() > 1 ? nodeName + format("#%zu", p) : nodeName;
                inst.mesh = mirrored ? mirroredCopy(parts[p]) : parts[p];
                inst.transform = world;
                scene_.instances.push_back(std::move(inst));
            }
            for (const PointLineSet& set : pointLineParts_[size_t(node.mesh)]) {
                scene_.pointLines.push_back(set);
                scene_.pointLines.back().name = nodeName + " " + set.name;
                scene_.pointLines.back().transform = world;
            }
        }
        glm::vec3 position = glm::vec3(world * glm::vec4(0, 0, 0, 1));
        glm::mat3 basis(world);
        glm::vec3 forward = basis * glm::vec3(0, 0, -1);
        if (node.camera >= 0) addCamera(node, index, position, forward, basis * glm::vec3(0, 1, 0));
        if (node.extras.IsObject() && node.extras.Has("shadel_gi_volume"))
            addGiVolume(node.extras.Get("shadel_gi_volume"), nodeName, index, world);
        if (auto it = node.extensions.find("KHR_lights_punctual"); it != node.extensions.end()) {
            const tinygltf::Value& light = it->second.Get("light");
            if (light.IsNumber()) addLight(light.GetNumberAsInt(), nodeName, position, forward);
        }
    }

    // extras "shadel_gi_volume": true -> the node's unit cube in world space is a local GI volume.
    void addGiVolume(const tinygltf::Value& flag, const std::string& name, int index,
                     const glm::mat4& world) {
        if (!flag.IsBool()) {
            warn(format("node %d: extras.shadel_gi_volume is not a boolean; ignored", index));
            return;
        }
        if (!flag.Get<bool>()) return;
        Aabb box;
        for (int c = 0; c < 8; ++c)
            box.extend(
                glm::vec3(world * glm::vec4(c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1, 1)));
        glm::vec3 e = box.extent();
        if (!(std::min(e.x, std::min(e.y, e.z)) > 1e-4f) || !std::isfinite(e.x + e.y + e.z)) {
            warn(format("node %d: GI volume '%s' has a degenerate box; ignored", index,
                        name.c_str()));
            return;
        }
        scene_.giVolumes.push_back({name, box});
    }

    void addCamera(const tinygltf::Node& node, int nodeIndex, glm::vec3 position, glm::vec3 forward,
                   glm::vec3 up) {
        const tinygltf::Camera& cam = model_.cameras[size_t(node.camera)];
        bool ortho = cam.type == "orthographic";
        if (cam.type != "perspective" && !ortho) {
            warn(format("camera %d has unknown type '%s'; skipped", node.camera, cam.type.c_str()));
            return;
        }
        Camera out;
        out.name = !cam.name.empty()    ? cam.name
                   : !node.name.empty() ? node.name
                                        : format("camera%d", nodeIndex);
        float fl = glm::length(forward);
        if (!(fl > 1e-12f)) {
            warn(format("camera %d on node %d has a degenerate transform; skipped", node.camera,
                        nodeIndex));
            return;
        }
        out.position = position;
        out.forward = forward / fl;
        up -= out.forward * glm::dot(up, out.forward);
        out.up = glm::length(up) > 1e-12f ? glm::normalize(up) : glm::vec3(0, 1, 0);
        bool hasFar = false;
        if (ortho) {
            // The node's scale does not scale the view (glTF: camera transforms are rigid).
            float ymag = std::abs(float(cam.orthographic.ymag));
            if (!(ymag > 0.0f) || !std::isfinite(ymag)) {
                warn(format("orthographic camera %d has ymag %g; skipped", node.camera,
                            cam.orthographic.ymag));
                return;
            }
            out.orthoHalfHeight = ymag;
            out.znear = std::max(float(cam.orthographic.znear), ymag * 1e-6f);
            hasFar = cam.orthographic.zfar > cam.orthographic.znear;
            if (hasFar) out.zfar = float(cam.orthographic.zfar);
        } else {
            out.yfov = float(cam.perspective.yfov);
            out.znear = float(cam.perspective.znear);
            hasFar = cam.perspective.zfar > cam.perspective.znear;
            if (hasFar) out.zfar = float(cam.perspective.zfar);
        }
        scene_.cameras.push_back(out);
        cameraZfarGiven_.push_back(hasFar);
    }

    void addLight(int index, const std::string& nodeName, glm::vec3 position, glm::vec3 direction) {
        if (index < 0 || size_t(index) >= model_.lights.size())
            error(format("node '%s' references light %d, which does not exist", nodeName.c_str(),
                         index));
        const tinygltf::Light& l = model_.lights[size_t(index)];
        Light out;
        out.name = l.name.empty() ? nodeName : l.name;
        out.type = l.type == "directional" ? LightType::Directional
                   : l.type == "spot"      ? LightType::Spot
                                           : LightType::Point;
        if (l.color.size() == 3)
            out.color = {float(l.color[0]), float(l.color[1]), float(l.color[2])};
        out.intensity = float(l.intensity);
        out.position = position;
        float len = glm::length(direction);
        out.direction = len > 1e-12f ? direction / len : glm::vec3(0, 0, -1);
        out.range = float(l.range);
        out.innerConeAngle = float(l.spot.innerConeAngle);
        out.outerConeAngle = float(l.spot.outerConeAngle);
        if (out.type == LightType::Directional) {
            // The renderer has one shadowed sun: the first directional light.
            bool haveSun = false;
            for (const Light& other : scene_.lights) haveSun |= other.castsShadow;
            out.castsShadow = !haveSun;
        }
        scene_.lights.push_back(out);
    }

    // The scene's root nodes, then a depth-first walk with an explicit stack (a long chain of
    // nodes must not overflow the call stack). glTF node graphs are disjoint trees: a node
    // reached twice means a cycle or a shared child, both invalid.
    // A skinned node's own mesh copy, its vertices moved by sum(weight x world(joint) x
    // inverseBind) (glTF skinning, evaluated on the CPU once per run); the node's transform is
    // ignored, as glTF specifies.
    void addSkinnedMesh(const tinygltf::Node& node, int index, const std::string& nodeName) {
        const tinygltf::Skin& skin = model_.skins[size_t(node.skin)];
        std::vector<glm::mat4> joints(skin.joints.size(), glm::mat4(1.0f));
        std::vector<float> ibm;
        if (skin.inverseBindMatrices >= 0) {
            ibm = readFloats(skin.inverseBindMatrices, 16, "inverseBindMatrices");
            if (ibm.size() / 16 < skin.joints.size())
                error(format("skin %d has %zu inverse bind matrices for %zu joints", node.skin,
                             ibm.size() / 16, skin.joints.size()));
        }
        for (size_t j = 0; j < skin.joints.size(); ++j) {
            int joint = skin.joints[j];
            if (joint < 0 || size_t(joint) >= model_.nodes.size())
                error(format("skin %d joint %zu is not a node", node.skin, j));
            glm::mat4 inverseBind = ibm.empty() ? glm::mat4(1.0f) : glm::make_mat4(&ibm[j * 16]);
            joints[j] = worldOf_[size_t(joint)] * inverseBind;
        }
        const tinygltf::Mesh& gm = model_.meshes[size_t(node.mesh)];
        const std::vector<double>& weights = node.weights.empty() ? gm.weights : node.weights;
        const uint32_t poseIndex = uint32_t(scene_.skinPoses.size()); // this node's joints
        for (size_t p = 0; p < gm.primitives.size(); ++p) {
            const tinygltf::Primitive& prim = gm.primitives[p];
            std::string where =
                format("mesh %d primitive %zu (skinned, node %d)", node.mesh, p, index);
            std::optional<Mesh> mesh = convertPrimitive(prim, where, weights);
            if (!mesh) continue;
            auto j = prim.attributes.find("JOINTS_0");
            auto w = prim.attributes.find("WEIGHTS_0");
            if (j != prim.attributes.end() && w != prim.attributes.end()) {
                std::vector<float> ji = readFloats(j->second, 4, "JOINTS_0");
                std::vector<float> wi = readFloats(w->second, 4, "WEIGHTS_0");
                size_t count = mesh->vertices.size();
                if (ji.size() != count * 4 || wi.size() != count * 4)
                    error(where + ": JOINTS_0/WEIGHTS_0 do not match POSITION");
                // The unskinned vertices and influences, for GPU skinning (render/skinning).
                auto skinData = std::make_shared<MeshSkin>();
                skinData->skin = poseIndex;
                skinData->bindVertices = mesh->vertices;
                skinData->joints.resize(count);
                skinData->weights.resize(count);
                for (size_t v = 0; v < count; ++v) {
                    glm::mat4 m(0.0f);
                    for (int k = 0; k < 4; ++k) {
                        float jf = ji[v * 4 + size_t(k)];
                        if (!(jf >= 0.0f) || size_t(jf) >= joints.size())
                            error(format("%s: vertex %zu joint %g out of range (%zu joints)",
                                         where.c_str(), v, jf, joints.size()));
                        m += joints[size_t(jf)] * wi[v * 4 + size_t(k)];
                        skinData->joints[v][k] = uint32_t(jf);
                        skinData->weights[v][k] = wi[v * 4 + size_t(k)];
                    }
                    Vertex& vert = mesh->vertices[v];
                    vert.position = glm::vec3(m * glm::vec4(vert.position, 1.0f));
                    glm::mat3 n = glm::transpose(glm::inverse(glm::mat3(m)));
                    vert.normal = n * vert.normal;
                    vert.tangent =
                        glm::vec4(glm::mat3(m) * glm::vec3(vert.tangent), vert.tangent.w);
                    if (!finite3(vert.position))
                        error(format("%s: vertex %zu skinned to a non-finite position",
                                     where.c_str(), v));
                }
                sanitizeNormalsAndTangents(*mesh);
                computeBounds(*mesh);
                mesh->skin = std::move(skinData);
                if (scene_.skinPoses.size() == poseIndex) scene_.skinPoses.push_back({joints});
            }
            mesh->name = (gm.name.empty() ? format("mesh%d", node.mesh) : gm.name) +
                         format(" (skinned, node %d)", index);
            std::vector<Mesh> parts = splitMesh(std::move(*mesh));
            // Parts renumber the vertices: only a whole mesh keeps its GPU skinning input.
            if (parts.size() > 1)
                for (Mesh& part : parts) part.skin.reset();
            for (size_t k = 0; k < parts.size(); ++k) {
                Instance inst;
                inst.name = nodeName + (parts.size() > 1 ? format("#%zu", k) : std::string());
                inst.mesh = uint32_t(scene_.meshes.size());
                scene_.meshes.push_back(std::move(parts[k]));
                scene_.instances.push_back(std::move(inst)); // identity: already in world space
            }
        }
    }

    void traverseNodes() {
        std::vector<int> roots;
        int sceneIndex = model_.defaultScene >= 0 ? model_.defaultScene
                         : model_.scenes.empty()  ? -1
                                                  : 0;
        if (sceneIndex >= 0) {
            roots = model_.scenes[size_t(sceneIndex)].nodes;
        } else {
            // No scene: take every node that is nobody's child.
            std::vector<bool> isChild(model_.nodes.size(), false);
            for (const auto& n : model_.nodes)
                for (int c : n.children) isChild[size_t(c)] = true;
            for (size_t i = 0; i < model_.nodes.size(); ++i)
                if (!isChild[i]) roots.push_back(int(i));
        }
        std::vector<bool> visited(model_.nodes.size(), false);
        std::vector<std::pair<int, glm::mat4>> stack;
        for (auto it = roots.rbegin(); it != roots.rend(); ++it)
            stack.emplace_back(*it, glm::mat4(1.0f));
        // World transforms first (skins need their joints'), then the content in walk order.
        worldOf_.assign(model_.nodes.size(), glm::mat4(1.0f));
        std::vector<int> order;
        while (!stack.empty()) {
            auto [index, parent] = stack.back();
            stack.pop_back();
            if (visited[size_t(index)])
                error(format("node %d is reached twice (cyclic or shared node hierarchy)", index));
            visited[size_t(index)] = true;
            const tinygltf::Node& node = model_.nodes[size_t(index)];
            glm::mat4 world = parent * localMatrix(node, index);
            if (!finiteMatrix(world))
                error(format("node %d has a non-finite world transform", index));
            worldOf_[size_t(index)] = world;
            order.push_back(index);
            for (auto c = node.children.rbegin(); c != node.children.rend(); ++c)
                stack.emplace_back(*c, world);
        }
        for (int index : order)
            addNodeContent(model_.nodes[size_t(index)], index, worldOf_[size_t(index)]);
    }

    void finishCamerasAndLights() {
        Aabb bounds = scene_.worldBounds();
        glm::vec3 centre = bounds.center();
        float radius = std::max(0.5f * glm::length(bounds.extent()), 1e-3f);
        for (size_t i = 0; i < scene_.cameras.size(); ++i) {
            if (cameraZfarGiven_[i]) continue;
            // Infinite far plane in the file: pick one that contains the whole scene.
            Camera& cam = scene_.cameras[i];
            cam.zfar =
                std::max(cam.znear * 1000.0f, (glm::length(cam.position - centre) + radius) * 1.5f);
        }
        if (scene_.cameras.empty()) {
            Camera cam;
            cam.name = "auto";
            glm::vec3 dir = glm::normalize(glm::vec3(1.0f, 0.6f, 1.0f));
            float distance = radius / std::sin(cam.yfov * 0.5f) * 1.1f;
            cam.position = centre + dir * distance;
            cam.forward = -dir;
            glm::vec3 up =
                glm::vec3(0, 1, 0) - cam.forward * glm::dot(glm::vec3(0, 1, 0), cam.forward);
            cam.up = glm::normalize(up);
            cam.znear = std::max(distance - radius, radius * 0.01f) * 0.5f;
            cam.zfar = (distance + radius) * 2.0f;
            cam.automatic = true; // refitted tightly for the run (render/camera_framing.h)
            scene_.cameras.push_back(cam);
            SHADEL_INFO("%s: no camera in the file; using an automatic one framing the scene",
                        input_.c_str());
        }
        bool directional =
            std::any_of(scene_.lights.begin(), scene_.lights.end(),
                        [](const Light& l) { return l.type == LightType::Directional; });
        if (addDefaultSun_ && !directional) {
            Light sun;
            sun.name = "auto-sun";
            sun.type = LightType::Directional;
            sun.direction = glm::normalize(glm::vec3(-0.35f, -1.0f, -0.45f));
            sun.intensity = 3.0f;
            sun.castsShadow = true;
            scene_.lights.push_back(sun);
            SHADEL_INFO("%s: no directional light in the file; adding a default sun",
                        input_.c_str());
        }
    }
};

} // namespace

Scene importGltf(const std::string& path, const SceneFileOptions& options) {
    return importGltfBytes(readWholeFile(path, path), path, options);
}

Scene importGltfBytes(std::vector<uint8_t> bytes, const std::string& path,
                      const SceneFileOptions& options) {
    const std::string& input = path;
    if (bytes.size() > kMaxFileBytes) fail(input, "file is larger than the size limit");
    bool binary = bytes.size() >= 4 && readU32(bytes.data()) == kGlbMagic;

    json document = parseJson(jsonTextOf(bytes, binary, input), input);
    checkCounts(document, input);
    JsonSchemaCheck(document, input).run();
    checkRequiredGltfExtensions(document, input);
    std::string extensionsWarning = ignoredExtensionsWarning(ignoredGltfExtensions(document));
    if (!options.allowExternalFiles) checkUrisStayInFolder(document, input);
    MeshoptPlan meshopt = prepareMeshopt(document, input);
    if (!meshopt.fallbacks.empty()) bytes = withJsonText(bytes, binary, document.dump());
    document = json(); // tinygltf parses its own copy

    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(decodeImageToRgba8, nullptr);
    std::string baseDir = std::filesystem::path(path).parent_path().string();
    FileAccess access{baseDir, options.allowExternalFiles};
    loader.SetFsCallbacks({fsFileExists, fsExpandPath, fsReadWholeFile, fsWriteWholeFile, &access});
    tinygltf::Model model;
    std::string err, warn;
    bool ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(),
                                                   unsigned(bytes.size()), baseDir)
                     : loader.LoadASCIIFromString(&model, &err, &warn,
                                                  reinterpret_cast<const char*>(bytes.data()),
                                                  unsigned(bytes.size()), baseDir);
    if (!warn.empty()) {
        size_t start = 0;
        while (start < warn.size()) {
            size_t end = warn.find('\n', start);
            if (end == std::string::npos) end = warn.size();
            if (end > start)
                SHADEL_WARN("%s: %s", input.c_str(), warn.substr(start, end - start).c_str());
            start = end + 1;
        }
    }
    if (!ok || !err.empty()) fail(input, oneLine(err.empty() ? "glTF loader failed" : err));
    decodeMeshopt(meshopt, model, input);
    if (options.time)
        poseAnimations(model, *options.time, input,
                       [&](const std::string& w) { SHADEL_WARN("%s", w.c_str()); });
    bytes.clear();
    bytes.shrink_to_fit();

    Scene scene;
    scene.name = std::filesystem::path(path).stem().string();
    if (!extensionsWarning.empty()) SHADEL_WARN("%s: %s", input.c_str(), extensionsWarning.c_str());
    GltfConverter(model, input, scene, options.time.has_value(), options.addDefaultSun).run();
    return scene;
}

} // namespace shadel
