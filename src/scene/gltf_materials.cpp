#include "scene/gltf_materials.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/log.h"

namespace shadel {

namespace {

const tinygltf::Value* extension(const tinygltf::ExtensionMap& map, const char* name) {
    auto it = map.find(name);
    return it == map.end() || !it->second.IsObject() ? nullptr : &it->second;
}

float number(const tinygltf::Value& obj, const char* key, float fallback) {
    if (!obj.Has(key)) return fallback;
    const tinygltf::Value& v = obj.Get(key);
    return v.IsNumber() || v.IsInt() ? float(v.GetNumberAsDouble()) : fallback;
}

glm::vec3 vec3Of(const tinygltf::Value& obj, const char* key, glm::vec3 fallback) {
    if (!obj.Has(key)) return fallback;
    const tinygltf::Value& v = obj.Get(key);
    if (!v.IsArray() || v.ArrayLen() < 3) return fallback;
    glm::vec3 out;
    for (int i = 0; i < 3; ++i) out[i] = float(v.Get(i).GetNumberAsDouble());
    return out;
}

// A texture info written as a JSON value (inside another extension).
struct ValueTextureInfo {
    int index = -1, texCoord = 0;
    float scale = 1.0f;
    UvTransform transform;
};
ValueTextureInfo textureInfoOf(const tinygltf::Value& obj, const char* key) {
    ValueTextureInfo out;
    if (!obj.Has(key) || !obj.Get(key).IsObject()) return out;
    const tinygltf::Value& t = obj.Get(key);
    if (t.Has("index")) out.index = t.Get("index").GetNumberAsInt();
    if (t.Has("texCoord")) out.texCoord = t.Get("texCoord").GetNumberAsInt();
    out.scale = number(t, "scale", 1.0f);
    if (t.Has("extensions") && t.Get("extensions").IsObject()) {
        tinygltf::ExtensionMap map;
        const tinygltf::Value& ext = t.Get("extensions");
        for (const std::string& k : ext.Keys()) map[k] = ext.Get(k);
        out.transform = uvTransformOf(map);
        out.texCoord = texCoordOf(map, out.texCoord);
    }
    return out;
}

// Records a texture slot's UV transform, UV set (texCoord, KHR_texture_transform's override
// applied) and sampler. Vertices carry two UV sets: a slot naming a third reads the first,
// with a warning naming the material and the slot.
void setSlot(Material& m, TextureSlot slot, int32_t texture, int gltfTexture,
             const UvTransform& transform, int texCoord, const MaterialTextures& t,
             const char* name) {
    uint32_t s = uint32_t(slot);
    m.uvTransforms[s] = transform;
    m.texCoords[s] = texture != kNoTexture && texCoord == 1 ? 1 : 0;
    if (texture != kNoTexture && texCoord >= 2 && t.warn)
        t.warn(format("material '%s': its %s texture reads TEXCOORD_%d, which is not supported "
                      "(only TEXCOORD_0 and TEXCOORD_1 are imported); it reads TEXCOORD_0",
                      m.name.c_str(), name, texCoord));
    if (texture != kNoTexture && t.sampler) m.samplers[s] = t.sampler(gltfTexture);
}

// KHR_materials_pbrSpecularGlossiness as metal/rough: a specular-glossiness material is a
// dielectric whose F0 is its specular colour, i.e. metallic 0, base colour = diffuse,
// roughness = 1 - glossiness, and KHR_materials_specular's colour = specular / 0.04 (the F0 of
// ior 1.5), so F0 = min(0.04 x colour, 1) = specular. This is the conversion glTF tools use; the
// diffuse term differs from the legacy model by (1 - F) against (1 - max(specular)), which is
// small. Per-texel specular colour is not kept (the factor is), glossiness is.
void convertSpecularGlossiness(const tinygltf::Value& sg, int index, Material& out,
                               const MaterialTextures& t) {
    glm::vec4 diffuse(1.0f);
    if (sg.Has("diffuseFactor") && sg.Get("diffuseFactor").IsArray() &&
        sg.Get("diffuseFactor").ArrayLen() >= 4)
        for (int i = 0; i < 4; ++i)
            diffuse[i] = float(sg.Get("diffuseFactor").Get(i).GetNumberAsDouble());
    glm::vec3 specular = vec3Of(sg, "specularFactor", glm::vec3(1.0f));
    float glossiness = std::clamp(number(sg, "glossinessFactor", 1.0f), 0.0f, 1.0f);
    out.baseColorFactor = diffuse;
    out.metallicFactor = 0.0f;
    out.roughnessFactor = 1.0f - glossiness;
    out.ior = 1.5f;
    out.specularFactor = 1.0f;
    out.specularColorFactor = glm::clamp(specular / 0.04f, glm::vec3(0.0f), glm::vec3(25.0f));
    ValueTextureInfo dt = textureInfoOf(sg, "diffuseTexture");
    if (dt.index >= 0) {
        out.baseColorTexture = t.resolve(dt.index, true, "diffuse");
        setSlot(out, TextureSlot::BaseColor, out.baseColorTexture, dt.index, dt.transform,
                dt.texCoord, t, "diffuse");
    }
    ValueTextureInfo gt = textureInfoOf(sg, "specularGlossinessTexture");
    if (gt.index >= 0) {
        out.metallicRoughnessTexture = t.glossinessToRoughness(gt.index, glossiness);
        if (out.metallicRoughnessTexture != kNoTexture) {
            out.roughnessFactor = 1.0f; // the texture holds 1 - glossiness x factor
            out.metallicFactor = 0.0f;
            setSlot(out, TextureSlot::MetallicRoughness, out.metallicRoughnessTexture, gt.index,
                    gt.transform, gt.texCoord, t, "specular-glossiness");
        }
        t.warn(format("material %d: the specular colour of specularGlossinessTexture is not "
                      "kept (specularFactor is); its glossiness is",
                      index));
    }
}

// KHR_materials_transmission (factor x texture R) and KHR_materials_volume (thickness factor x
// texture G, in the mesh's space; attenuation colour and distance, infinite by default). The
// volume extension means nothing without transmission, so it is read only beside it.
void applyTransmission(const tinygltf::Material& gm, Material& out, const MaterialTextures& t) {
    const tinygltf::Value* tr = extension(gm.extensions, "KHR_materials_transmission");
    if (!tr) return;
    out.transmissionFactor = std::clamp(number(*tr, "transmissionFactor", 0.0f), 0.0f, 1.0f);
    if (ValueTextureInfo info = textureInfoOf(*tr, "transmissionTexture"); info.index >= 0) {
        out.transmissionTexture = t.resolve(info.index, false, "transmission");
        setSlot(out, TextureSlot::Transmission, out.transmissionTexture, info.index, info.transform,
                info.texCoord, t, "transmission");
    }
    const tinygltf::Value* vol = extension(gm.extensions, "KHR_materials_volume");
    if (!vol) return;
    out.thicknessFactor = std::max(number(*vol, "thicknessFactor", 0.0f), 0.0f);
    out.attenuationColor = glm::clamp(vec3Of(*vol, "attenuationColor", glm::vec3(1.0f)),
                                      glm::vec3(0.0f), glm::vec3(1.0f));
    float distance = number(*vol, "attenuationDistance", 0.0f);
    out.attenuationDistance = distance > 0.0f ? distance : std::numeric_limits<float>::infinity();
    if (ValueTextureInfo info = textureInfoOf(*vol, "thicknessTexture"); info.index >= 0) {
        out.thicknessTexture = t.resolve(info.index, false, "thickness");
        setSlot(out, TextureSlot::Thickness, out.thicknessTexture, info.index, info.transform,
                info.texCoord, t, "thickness");
    }
}

} // namespace

TextureSampler gltfTextureSampler(const tinygltf::Model& model, int texture) {
    TextureSampler out;
    int sampler = model.textures[size_t(texture)].sampler;
    if (sampler < 0 || size_t(sampler) >= model.samplers.size()) return out;
    const tinygltf::Sampler& s = model.samplers[size_t(sampler)];
    auto wrap = [](int mode) -> uint8_t {
        return mode == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE     ? SAMPLER_WRAP_CLAMP_TO_EDGE
               : mode == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? SAMPLER_WRAP_MIRRORED_REPEAT
                                                               : SAMPLER_WRAP_REPEAT;
    };
    out.wrapS = wrap(s.wrapS);
    out.wrapT = wrap(s.wrapT);
    if (s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST) out.mag = SAMPLER_MAG_NEAREST;
    switch (s.minFilter) {
    case TINYGLTF_TEXTURE_FILTER_NEAREST:
        out.min = SAMPLER_MIN_NEAREST;
        break;
    case TINYGLTF_TEXTURE_FILTER_LINEAR:
        out.min = SAMPLER_MIN_LINEAR;
        break;
    case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST:
        out.min = SAMPLER_MIN_NEAREST_MIPMAP_NEAREST;
        break;
    case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_NEAREST:
        out.min = SAMPLER_MIN_LINEAR_MIPMAP_NEAREST;
        break;
    case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR:
        out.min = SAMPLER_MIN_NEAREST_MIPMAP_LINEAR;
        break;
    default:
        break; // LINEAR_MIPMAP_LINEAR, or unset
    }
    return out;
}

UvTransform uvTransformOf(const tinygltf::ExtensionMap& map) {
    UvTransform out;
    const tinygltf::Value* tt = extension(map, "KHR_texture_transform");
    if (!tt) return out;
    glm::vec2 offset(0.0f), scale(1.0f);
    if (tt->Has("offset") && tt->Get("offset").ArrayLen() >= 2)
        offset = {float(tt->Get("offset").Get(0).GetNumberAsDouble()),
                  float(tt->Get("offset").Get(1).GetNumberAsDouble())};
    if (tt->Has("scale") && tt->Get("scale").ArrayLen() >= 2)
        scale = {float(tt->Get("scale").Get(0).GetNumberAsDouble()),
                 float(tt->Get("scale").Get(1).GetNumberAsDouble())};
    float rotation = number(*tt, "rotation", 0.0f);
    // The extension's matrix T * R * S. Its GLSL listing writes R's entries row by row
    // (cos, sin; -sin, cos): as a column-major mat3 the columns are (cos, -sin) and (sin, cos),
    // which is what TextureTransformTest's markers confirm (the other sign hits the red one).
    float c = std::cos(rotation), s = std::sin(rotation);
    out.c0 = glm::vec2(c, -s) * scale.x;
    out.c1 = glm::vec2(s, c) * scale.y;
    out.c2 = offset;
    return out;
}

int texCoordOf(const tinygltf::ExtensionMap& map, int texCoord) {
    const tinygltf::Value* tt = extension(map, "KHR_texture_transform");
    if (!tt || !tt->Has("texCoord") || !tt->Get("texCoord").IsNumber()) return texCoord;
    return tt->Get("texCoord").GetNumberAsInt();
}

void applyMaterialExtensions(const tinygltf::Material& gm, int index, Material& out,
                             const MaterialTextures& t) {
    const auto& pbr = gm.pbrMetallicRoughness;
    auto core = [&](TextureSlot slot, int32_t texture, const tinygltf::TextureInfo& info,
                    const char* name) {
        setSlot(out, slot, texture, info.index, uvTransformOf(info.extensions),
                texCoordOf(info.extensions, info.texCoord), t, name);
    };
    core(TextureSlot::BaseColor, out.baseColorTexture, pbr.baseColorTexture, "base colour");
    core(TextureSlot::MetallicRoughness, out.metallicRoughnessTexture, pbr.metallicRoughnessTexture,
         "metal-roughness");
    setSlot(out, TextureSlot::Normal, out.normalTexture, gm.normalTexture.index,
            uvTransformOf(gm.normalTexture.extensions),
            texCoordOf(gm.normalTexture.extensions, gm.normalTexture.texCoord), t, "normal");
    core(TextureSlot::Emissive, out.emissiveTexture, gm.emissiveTexture, "emissive");
    setSlot(out, TextureSlot::Occlusion, out.occlusionTexture, gm.occlusionTexture.index,
            uvTransformOf(gm.occlusionTexture.extensions),
            texCoordOf(gm.occlusionTexture.extensions, gm.occlusionTexture.texCoord), t,
            "occlusion");

    if (const tinygltf::Value* es = extension(gm.extensions, "KHR_materials_emissive_strength"))
        out.emissiveFactor *= std::max(number(*es, "emissiveStrength", 1.0f), 0.0f);
    if (extension(gm.extensions, "KHR_materials_unlit")) out.unlit = true;
    if (const tinygltf::Value* sg =
            extension(gm.extensions, "KHR_materials_pbrSpecularGlossiness")) {
        // Metal/rough given beside it is the file's own fallback; the extension is the intent.
        convertSpecularGlossiness(*sg, index, out, t);
    }
    if (const tinygltf::Value* cc = extension(gm.extensions, "KHR_materials_clearcoat")) {
        out.clearcoatFactor = std::clamp(number(*cc, "clearcoatFactor", 0.0f), 0.0f, 1.0f);
        out.clearcoatRoughnessFactor =
            std::clamp(number(*cc, "clearcoatRoughnessFactor", 0.0f), 0.0f, 1.0f);
        struct CoatTexture {
            const char* key;
            TextureSlot slot;
            int32_t* target;
            const char* name;
        };
        const CoatTexture coat[] = {
            {"clearcoatTexture", TextureSlot::Clearcoat, &out.clearcoatTexture, "clearcoat"},
            {"clearcoatRoughnessTexture", TextureSlot::ClearcoatRoughness,
             &out.clearcoatRoughnessTexture, "clearcoat roughness"},
            {"clearcoatNormalTexture", TextureSlot::ClearcoatNormal, &out.clearcoatNormalTexture,
             "clearcoat normal"},
        };
        for (const CoatTexture& c : coat) {
            ValueTextureInfo info = textureInfoOf(*cc, c.key);
            if (info.index < 0) continue;
            *c.target = t.resolve(info.index, false, c.name);
            setSlot(out, c.slot, *c.target, info.index, info.transform, info.texCoord, t, c.name);
            if (c.slot == TextureSlot::ClearcoatNormal) out.clearcoatNormalScale = info.scale;
        }
    }
    if (const tinygltf::Value* ior = extension(gm.extensions, "KHR_materials_ior")) {
        // ior 0 means "infinitely reflective" (F0 = 1) in the spec; (ior-1)/(ior+1) gives that.
        float value = number(*ior, "ior", 1.5f);
        out.ior = value == 0.0f ? 0.0f : std::max(value, 1.0f);
    }
    if (const tinygltf::Value* sp = extension(gm.extensions, "KHR_materials_specular")) {
        out.specularFactor = std::clamp(number(*sp, "specularFactor", 1.0f), 0.0f, 1.0f);
        out.specularColorFactor =
            glm::max(vec3Of(*sp, "specularColorFactor", glm::vec3(1.0f)), glm::vec3(0.0f));
        // Strength in A (linear), F0 tint in RGB (sRGB).
        if (ValueTextureInfo info = textureInfoOf(*sp, "specularTexture"); info.index >= 0) {
            out.specularTexture = t.resolve(info.index, false, "specular");
            setSlot(out, TextureSlot::Specular, out.specularTexture, info.index, info.transform,
                    info.texCoord, t, "specular");
        }
        if (ValueTextureInfo info = textureInfoOf(*sp, "specularColorTexture"); info.index >= 0) {
            out.specularColorTexture = t.resolve(info.index, true, "specular colour");
            setSlot(out, TextureSlot::SpecularColor, out.specularColorTexture, info.index,
                    info.transform, info.texCoord, t, "specular colour");
        }
    }
    if (const tinygltf::Value* sh = extension(gm.extensions, "KHR_materials_sheen")) {
        out.sheenColorFactor = glm::clamp(vec3Of(*sh, "sheenColorFactor", glm::vec3(0.0f)),
                                          glm::vec3(0.0f), glm::vec3(1.0f));
        out.sheenRoughnessFactor =
            std::clamp(number(*sh, "sheenRoughnessFactor", 0.0f), 0.0f, 1.0f);
        // Colour in RGB (sRGB), roughness in A (linear).
        if (ValueTextureInfo info = textureInfoOf(*sh, "sheenColorTexture"); info.index >= 0) {
            out.sheenColorTexture = t.resolve(info.index, true, "sheen colour");
            setSlot(out, TextureSlot::SheenColor, out.sheenColorTexture, info.index, info.transform,
                    info.texCoord, t, "sheen colour");
        }
        if (ValueTextureInfo info = textureInfoOf(*sh, "sheenRoughnessTexture"); info.index >= 0) {
            out.sheenRoughnessTexture = t.resolve(info.index, false, "sheen roughness");
            setSlot(out, TextureSlot::SheenRoughness, out.sheenRoughnessTexture, info.index,
                    info.transform, info.texCoord, t, "sheen roughness");
        }
    }
    applyTransmission(gm, out, t);
}

} // namespace shadel
