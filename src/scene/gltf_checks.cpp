#include "scene/gltf_checks.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "core/error.h"
#include "core/log.h"
#include "scene/gltf_files.h"
#include "scene/gltf_uri.h"
#include "scene/json_limits.h"

namespace shadel::gltf {

namespace {

using json = nlohmann::json;

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
    // maxValue: what the importer's field holds (tinygltf keeps some as int: a larger value
    // would wrap silently).
    uint64_t requiredUint(const json& obj, const char* key, const std::string& p, uint64_t min = 0,
                          uint64_t maxValue = UINT64_MAX) {
        const json* v = member(obj, key);
        if (!v) bad(p, format("missing required '%s'", key));
        uint64_t value = uintValue(*v, child(p, key));
        if (value < min)
            bad(child(p, key), format("must be at least %llu", (unsigned long long)min));
        if (value > maxValue)
            bad(child(p, key), format("%llu is out of range (at most %llu)",
                                      (unsigned long long)value, (unsigned long long)maxValue));
        return value;
    }
    void optUint(const json& obj, const char* key, const std::string& p,
                 uint64_t maxValue = UINT64_MAX) {
        if (member(obj, key)) requiredUint(obj, key, p, 0, maxValue);
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
            requiredUint(s, "count", sp, 1, INT32_MAX);
            for (const char* part : {"indices", "values"}) {
                const json* o = member(s, part);
                if (!o) bad(sp, format("missing required '%s'", part));
                optObject(s, part, sp, [&](const json& io, const std::string& ip) {
                    requiredIndex(io, "bufferView", ip, "bufferViews");
                    optUint(io, "byteOffset", ip, INT32_MAX);
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
            // A field of view of pi or more has no perspective projection.
            if (const json* yfov = member(persp, "yfov");
                yfov && yfov->is_number() && yfov->get<double>() >= 3.14159)
                bad(child(pp, "yfov"),
                    format("%g radians: a field of view must be below pi", yfov->get<double>()));
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

} // namespace

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

void checkSchema(const json& root, const std::string& input) {
    JsonSchemaCheck(root, input).run();
}

} // namespace shadel::gltf
