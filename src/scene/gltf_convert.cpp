#include "scene/gltf_convert.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "core/error.h"
#include "core/log.h"
#include "scene/gltf_accessors.h"
#include "scene/gltf_files.h"
#include "scene/gltf_materials.h"
#include "scene/gltf_uri.h"
#include "scene/load_budget.h"
#include "scene/mesh_utils.h"

namespace shadel::gltf {

namespace {

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
    GltfConverter(const tinygltf::Model& model, const std::string& input, Scene& scene,
                  bool skinning, bool addDefaultSun)
        : model_(model), input_(input), scene_(scene), accessors_(model, input),
          skinning_(skinning), addDefaultSun_(addDefaultSun) {}

    void run() {
        for (size_t i = 0; i < model_.accessors.size(); ++i) accessors_.validateAccessor(int(i));
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
    const tinygltf::Model& model_;
    const std::string& input_;
    Scene& scene_;
    AccessorReader accessors_;
    std::vector<std::vector<uint32_t>> meshParts_;
    std::vector<std::vector<PointLineSet>> pointLineParts_; // per glTF mesh, object space
    std::vector<bool> meshConverted_;
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

    // extras "shadel_material": the material program that shades it decoupled
    // (render/materials), a .shmat path relative to the glTF's folder and inside it, like the
    // model's other files, or "builtin:NAME". A program runs code: it is never read from
    // elsewhere, whatever --allow-external-files says.
    std::string materialProgram(const tinygltf::Material& m, int index) {
        if (!m.extras.IsObject() || !m.extras.Has("shadel_material")) return "";
        const tinygltf::Value& v = m.extras.Get("shadel_material");
        std::string where = format("material %d: extras.shadel_material", index);
        if (!v.IsString() || v.Get<std::string>().empty())
            error(where + ": expected a path string");
        std::string ref = v.Get<std::string>();
        if (ref.rfind("builtin:", 0) == 0) return ref;
        std::string decoded = decodeUriPath(ref);
        std::filesystem::path folder = std::filesystem::path(input_).parent_path();
        std::string path = (folder / decoded).lexically_normal().string();
        if (uriEscapesFolder(decoded) ||
            !pathInsideFolder(path, folder.empty() ? std::string(".") : folder.string()))
            error(where + " \"" + ref + "\" is outside the model's folder");
        return path;
    }

    Material convertMaterial(int index) {
        const tinygltf::Material& m = model_.materials[size_t(index)];
        const auto& pbr = m.pbrMetallicRoughness;
        Material out;
        out.name = m.name.empty() ? format("material %d", index) : m.name;
        out.shadelMaterial = materialProgram(m, index);
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
        std::vector<float> positions = accessors_.readFloats(it->second, 3, "POSITION");
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
            std::vector<float> data = accessors_.readFloats(c->second, components, "COLOR_0");
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
            idx = accessors_.readIndices(prim.indices);
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
        std::vector<float> positions = accessors_.readFloats(positionAccessor, 3, "POSITION");
        size_t vertexCount = positions.size() / 3;
        Mesh mesh;
        chargeLoadMemory(uint64_t(vertexCount) * sizeof(Vertex), "a mesh's vertices");
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
            std::vector<float> data = accessors_.readFloats(accessor, components, name);
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
            indices = accessors_.readIndices(prim.indices);
            for (uint32_t i : indices)
                if (i >= vertexCount)
                    error(format("accessor %d index %u out of range (vertex count %zu)",
                                 prim.indices, i, vertexCount));
        } else {
            indices.resize(vertexCount);
            for (size_t i = 0; i < vertexCount; ++i) indices[i] = uint32_t(i);
        }
        mesh.indices = triangulate(indices, mode, where);
        if (size_t repeated = removeDuplicateTriangles(mesh.indices); repeated > 0)
            warn(format("%s: %zu triangles repeat an earlier one (the same vertices, the same "
                        "winding); drawn once",
                        where.c_str(), repeated));
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
                std::vector<float> delta = accessors_.readFloats(accessor, 3, name.c_str());
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

    void addNodeContent(const tinygltf::Node& node, int index, const glm::mat4& world) {
        std::string nodeName = node.name.empty() ? format("node%d", index) : node.name;
        if (node.skin >= 0 && node.mesh >= 0 && skinning_) {
            addSkinnedMesh(node, index, nodeName);
        } else if (node.mesh >= 0) {
            if (node.skin >= 0)
                warnOnce("skinned meshes are drawn in their bind pose without --time");
            if (!meshConverted_[size_t(node.mesh)]) convertMesh(node.mesh, node.weights);
            // A mirroring transform turns counter-clockwise into clockwise: the renderer draws
            // such instances with the clockwise front face, deciding every frame (the sign may
            // change while an animation plays), so the mesh is shared as it is.
            const auto& parts = meshParts_[size_t(node.mesh)];
            for (size_t p = 0; p < parts.size(); ++p) {
                chargeLoadMemory(sizeof(Instance), "an instance");
                Instance inst;
                inst.name = parts.size() > 1 ? nodeName + format("#%zu", p) : nodeName;
                inst.mesh = parts[p];
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
            ibm = accessors_.readFloats(skin.inverseBindMatrices, 16, "inverseBindMatrices");
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
                std::vector<float> ji = accessors_.readFloats(j->second, 4, "JOINTS_0");
                std::vector<float> wi = accessors_.readFloats(w->second, 4, "WEIGHTS_0");
                size_t count = mesh->vertices.size();
                if (ji.size() != count * 4 || wi.size() != count * 4)
                    error(where + ": JOINTS_0/WEIGHTS_0 do not match POSITION");
                // The unskinned vertices and influences, for GPU skinning (render/skinning).
                chargeLoadMemory(uint64_t(count) *
                                     (sizeof(Vertex) + sizeof(glm::uvec4) + sizeof(glm::vec4)),
                                 "a skinned mesh's bind pose");
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
        // Beyond this, 32-bit floats cannot place a camera or a near plane: squared lengths
        // overflow and depth has no precision left (a real scene in metres stays far below).
        constexpr float kMaxWorldCoordinate = 1e15f;
        if (bounds.valid()) {
            glm::vec3 reach = glm::max(glm::abs(bounds.min), glm::abs(bounds.max));
            float farthest = std::max({reach.x, reach.y, reach.z});
            if (!(farthest <= kMaxWorldCoordinate))
                error(format("the scene reaches %g units from the origin, beyond the %g that "
                             "32-bit floats can frame and render",
                             double(farthest), double(kMaxWorldCoordinate)));
        }
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

void convertModel(const tinygltf::Model& model, const std::string& input, Scene& scene,
                  bool skinning, bool addDefaultSun) {
    GltfConverter(model, input, scene, skinning, addDefaultSun).run();
}

} // namespace shadel::gltf
