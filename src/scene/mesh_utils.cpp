#include "scene/mesh_utils.h"

#include <cmath>
#include <unordered_set>

#include <glm/gtc/constants.hpp>

namespace shadel {

namespace {

bool isFinite(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Any unit vector perpendicular to n (n unit length).
glm::vec3 anyPerpendicular(glm::vec3 n) {
    glm::vec3 axis = std::abs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    return glm::normalize(glm::cross(axis, n));
}

// Procedural builders emit triangles in whatever order is convenient; this flips those whose
// geometric normal disagrees with the (outward) vertex normals so every mesh is CCW from
// outside, which is what back-face culling and the glTF convention expect.
void orientTrianglesOutward(Mesh& mesh) {
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const Vertex& a = mesh.vertices[mesh.indices[t]];
        const Vertex& b = mesh.vertices[mesh.indices[t + 1]];
        const Vertex& c = mesh.vertices[mesh.indices[t + 2]];
        glm::vec3 geometric = glm::cross(b.position - a.position, c.position - a.position);
        if (glm::dot(geometric, a.normal + b.normal + c.normal) < 0.0f)
            std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
    }
}

void finishProceduralMesh(Mesh& mesh) {
    orientTrianglesOutward(mesh);
    computeTangents(mesh);
    computeBounds(mesh);
}

} // namespace

void computeSmoothNormals(Mesh& mesh) {
    std::vector<glm::vec3> sum(mesh.vertices.size(), glm::vec3(0.0f));
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        uint32_t i0 = mesh.indices[t], i1 = mesh.indices[t + 1], i2 = mesh.indices[t + 2];
        glm::vec3 p0 = mesh.vertices[i0].position;
        // Cross product length is twice the area: larger triangles weigh more.
        glm::vec3 n = glm::cross(mesh.vertices[i1].position - p0, mesh.vertices[i2].position - p0);
        if (!isFinite(n)) continue;
        sum[i0] += n, sum[i1] += n, sum[i2] += n;
    }
    for (size_t v = 0; v < mesh.vertices.size(); ++v) {
        float len = glm::length(sum[v]);
        mesh.vertices[v].normal =
            (len > 0.0f && std::isfinite(len)) ? sum[v] / len : glm::vec3(0, 1, 0);
    }
}

void computeTangents(Mesh& mesh, int uvSet) {
    std::vector<glm::vec3> tangentSum(mesh.vertices.size(), glm::vec3(0.0f));
    std::vector<glm::vec3> bitangentSum(mesh.vertices.size(), glm::vec3(0.0f));
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        uint32_t idx[3] = {mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]};
        const Vertex& v0 = mesh.vertices[idx[0]];
        const Vertex& v1 = mesh.vertices[idx[1]];
        const Vertex& v2 = mesh.vertices[idx[2]];
        glm::vec3 e1 = v1.position - v0.position, e2 = v2.position - v0.position;
        auto uv = [uvSet](const Vertex& v) { return uvSet == 1 ? v.uv1 : v.uv0; };
        glm::vec2 d1 = uv(v1) - uv(v0), d2 = uv(v2) - uv(v0);
        float det = d1.x * d2.y - d2.x * d1.y;
        if (!(std::abs(det) > 1e-20f)) continue; // no UV parametrisation on this triangle
        glm::vec3 tangent = (e1 * d2.y - e2 * d1.y) / det;
        glm::vec3 bitangent = (e2 * d1.x - e1 * d2.x) / det;
        if (!isFinite(tangent) || !isFinite(bitangent)) continue;
        for (uint32_t i : idx) tangentSum[i] += tangent, bitangentSum[i] += bitangent;
    }
    for (size_t v = 0; v < mesh.vertices.size(); ++v) {
        Vertex& vert = mesh.vertices[v];
        glm::vec3 n = vert.normal;
        glm::vec3 t = tangentSum[v] - n * glm::dot(n, tangentSum[v]);
        float len = glm::length(t);
        if (!(len > 1e-12f) || !std::isfinite(len)) {
            vert.tangent = glm::vec4(anyPerpendicular(n), 1.0f);
            continue;
        }
        t /= len;
        float w = glm::dot(glm::cross(n, t), bitangentSum[v]) < 0.0f ? 1.0f : -1.0f;
        vert.tangent = glm::vec4(t, w);
    }
}

uint32_t sanitizeNormalsAndTangents(Mesh& mesh) {
    auto normalOk = [](glm::vec3 n) {
        float len = glm::length(n);
        return isFinite(n) && std::isfinite(len) && len > 1e-6f;
    };
    bool anyBadNormal = false;
    for (const Vertex& v : mesh.vertices) anyBadNormal |= !normalOk(v.normal);
    std::vector<glm::vec3> smooth;
    if (anyBadNormal) {
        // Bad normals are replaced by smooth ones computed from the geometry.
        Mesh copy;
        copy.vertices = mesh.vertices;
        copy.indices = mesh.indices;
        computeSmoothNormals(copy);
        smooth.reserve(copy.vertices.size());
        for (const Vertex& v : copy.vertices) smooth.push_back(v.normal);
    }
    uint32_t repaired = 0;
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
        Vertex& v = mesh.vertices[i];
        bool fixed = false;
        if (!normalOk(v.normal)) v.normal = smooth[i], fixed = true;
        v.normal = glm::normalize(v.normal);
        glm::vec3 t = glm::vec3(v.tangent);
        t -= v.normal * glm::dot(v.normal, t);
        float len = glm::length(t);
        if (!isFinite(t) || !(len > 1e-6f) || !std::isfinite(len)) {
            t = anyPerpendicular(v.normal);
            fixed = true;
        } else {
            t /= len;
        }
        float w = (std::isfinite(v.tangent.w) && v.tangent.w < 0.0f) ? -1.0f : 1.0f;
        v.tangent = glm::vec4(t, w);
        if (!std::isfinite(v.uv0.x) || !std::isfinite(v.uv0.y))
            v.uv0 = glm::vec2(0.0f), fixed = true;
        if (!std::isfinite(v.uv1.x) || !std::isfinite(v.uv1.y))
            v.uv1 = glm::vec2(0.0f), fixed = true;
        repaired += fixed ? 1 : 0;
    }
    return repaired;
}

void computeBounds(Mesh& mesh) {
    mesh.bounds = Aabb{};
    for (const Vertex& v : mesh.vertices) mesh.bounds.extend(v.position);
}

std::vector<Mesh> splitMesh(Mesh mesh, uint32_t maxTriangles) {
    std::vector<Mesh> parts;
    if (maxTriangles == 0 || mesh.triangleCount() <= maxTriangles) {
        parts.push_back(std::move(mesh));
        return parts;
    }
    const uint32_t triangleCount = mesh.triangleCount();
    const uint32_t partCount = (triangleCount + maxTriangles - 1) / maxTriangles;
    // remap[v] = index of source vertex v in the current part, valid when stamp[v] == part.
    std::vector<uint32_t> remap(mesh.vertices.size(), 0);
    std::vector<uint32_t> stamp(mesh.vertices.size(), UINT32_MAX);
    for (uint32_t part = 0; part < partCount; ++part) {
        Mesh out;
        out.name = mesh.name + "#" + std::to_string(part);
        out.material = mesh.material;
        uint32_t first = part * maxTriangles;
        uint32_t last = std::min(triangleCount, first + maxTriangles);
        out.indices.reserve(size_t(last - first) * 3);
        for (size_t i = size_t(first) * 3; i < size_t(last) * 3; ++i) {
            uint32_t src = mesh.indices[i];
            if (stamp[src] != part) {
                stamp[src] = part;
                remap[src] = uint32_t(out.vertices.size());
                out.vertices.push_back(mesh.vertices[src]);
            }
            out.indices.push_back(remap[src]);
        }
        computeBounds(out);
        parts.push_back(std::move(out));
    }
    return parts;
}

size_t removeDuplicateTriangles(std::vector<uint32_t>& indices) {
    struct Key {
        uint32_t a, b, c;
        bool operator==(const Key&) const = default;
    };
    struct KeyHash {
        size_t operator()(const Key& k) const {
            uint64_t h = (uint64_t(k.a) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(k.b) << 21) ^
                         (uint64_t(k.c) * 0xC2B2AE3D27D4EB4Full);
            return size_t(h ^ (h >> 29));
        }
    };
    std::unordered_set<Key, KeyHash> seen;
    seen.reserve(indices.size() / 3);
    size_t kept = 0;
    for (size_t t = 0; t + 2 < indices.size(); t += 3) {
        uint32_t a = indices[t], b = indices[t + 1], c = indices[t + 2];
        // The rotation that starts at the smallest index: one key per face and winding.
        Key key = a <= b && a <= c ? Key{a, b, c} : b <= c ? Key{b, c, a} : Key{c, a, b};
        if (!seen.insert(key).second) continue;
        indices[kept++] = a, indices[kept++] = b, indices[kept++] = c;
    }
    size_t removed = (indices.size() / 3) - kept / 3;
    indices.resize(kept);
    return removed;
}

std::string sceneInvariantViolation(const Scene& scene) {
    auto unit = [](glm::vec3 v) { return isFinite(v) && std::abs(glm::length(v) - 1.0f) < 1e-3f; };
    auto textureOk = [&](int32_t t) {
        return t == kNoTexture || (t >= 0 && size_t(t) < scene.textures.size());
    };
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        std::string where = "mesh " + std::to_string(m) + " '" + mesh.name + "'";
        if (mesh.indices.empty() || mesh.indices.size() % 3 != 0) return where + ": index count";
        if (mesh.triangleCount() > kMaxTrianglesPerMesh) return where + ": too many triangles";
        if (mesh.material >= scene.materials.size()) return where + ": material index";
        for (uint32_t i : mesh.indices)
            if (i >= mesh.vertices.size()) return where + ": index out of range";
        for (size_t v = 0; v < mesh.vertices.size(); ++v) {
            const Vertex& vert = mesh.vertices[v];
            std::string at = where + " vertex " + std::to_string(v);
            if (!isFinite(vert.position)) return at + ": position not finite";
            if (!std::isfinite(vert.uv0.x) || !std::isfinite(vert.uv0.y) ||
                !std::isfinite(vert.uv1.x) || !std::isfinite(vert.uv1.y))
                return at + ": uv not finite";
            if (!unit(vert.normal)) return at + ": normal not unit length";
            if (!unit(glm::vec3(vert.tangent))) return at + ": tangent not unit length";
            if (std::abs(glm::dot(vert.normal, glm::vec3(vert.tangent))) > 1e-3f)
                return at + ": tangent not perpendicular to normal";
            if (vert.tangent.w != 1.0f && vert.tangent.w != -1.0f) return at + ": tangent w not ±1";
            if (mesh.bounds.valid() && (glm::any(glm::lessThan(vert.position, mesh.bounds.min)) ||
                                        glm::any(glm::greaterThan(vert.position, mesh.bounds.max))))
                return at + ": outside mesh bounds";
        }
        if (!mesh.bounds.valid()) return where + ": bounds not set";
    }
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        const Material& mat = scene.materials[i];
        if (!textureOk(mat.baseColorTexture) || !textureOk(mat.metallicRoughnessTexture) ||
            !textureOk(mat.normalTexture) || !textureOk(mat.emissiveTexture) ||
            !textureOk(mat.occlusionTexture) || !textureOk(mat.specularTexture) ||
            !textureOk(mat.specularColorTexture) || !textureOk(mat.sheenColorTexture) ||
            !textureOk(mat.sheenRoughnessTexture) || !textureOk(mat.clearcoatTexture) ||
            !textureOk(mat.clearcoatRoughnessTexture) || !textureOk(mat.clearcoatNormalTexture) ||
            !textureOk(mat.transmissionTexture) || !textureOk(mat.thicknessTexture))
            return "material " + std::to_string(i) + ": texture index out of range";
    }
    for (const PointLineSet& set : scene.pointLines) {
        std::string where = "points/lines '" + set.name + "'";
        if (set.material >= scene.materials.size()) return where + ": material index";
        if (set.lines && set.vertices.size() % 2 != 0) return where + ": odd line vertex count";
        if (!set.colors.empty() && set.colors.size() != set.vertices.size())
            return where + ": colour count";
        for (const Vertex& v : set.vertices)
            if (!isFinite(v.position)) return where + ": position not finite";
    }
    for (size_t i = 0; i < scene.textures.size(); ++i) {
        const Texture& tex = scene.textures[i];
        size_t texels = size_t(tex.width) * tex.height * 4;
        if (tex.width == 0 || tex.height == 0 ||
            tex.rgba8.size() != (tex.procedural.kind != 0 ? 0 : texels))
            return "texture " + std::to_string(i) + ": size";
    }
    for (const Light& l : scene.lights)
        if (!textureOk(l.texture) || !(l.areaSize.x > 0.0f && l.areaSize.y > 0.0f))
            return "light '" + l.name + "': texture index or area size";
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        if (inst.mesh >= scene.meshes.size())
            return "instance " + std::to_string(i) + ": mesh index";
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r)
                if (!std::isfinite(inst.transform[c][r]))
                    return "instance " + std::to_string(i) + ": transform not finite";
    }
    for (const Camera& cam : scene.cameras) {
        if (!isFinite(cam.position) || !unit(cam.forward) || !unit(cam.up) ||
            std::abs(glm::dot(cam.forward, cam.up)) > 1e-3f || !(cam.znear > 0.0f) ||
            !(cam.zfar > cam.znear) || !(cam.yfov > 0.0f && cam.yfov < 3.14159f))
            return "camera '" + cam.name + "': invalid";
    }
    for (const Light& light : scene.lights) {
        if (!isFinite(light.position) || !unit(light.direction) || !isFinite(light.color) ||
            !std::isfinite(light.intensity) || light.intensity < 0.0f)
            return "light '" + light.name + "': invalid";
        for (uint32_t b : light.blockers)
            if (b >= scene.blockers.size())
                return "light '" + light.name + "': blocker " + std::to_string(b) +
                       " does not exist";
        if (light.blockers.size() > 32) return "light '" + light.name + "': more than 32 blockers";
    }
    for (const LightBlocker& b : scene.blockers) {
        if (!isFinite(b.center) || !unit(b.axisU) || !unit(b.axisV) ||
            std::abs(glm::dot(b.axisU, b.axisV)) > 1e-3f || !(b.halfSize.x > 0.0f) ||
            !(b.halfSize.y > 0.0f) || !std::isfinite(b.halfSize.x) || !std::isfinite(b.halfSize.y))
            return "light blocker '" + b.name + "': invalid";
    }
    return {};
}

Mesh makeBox(const std::string& name, glm::vec3 size, uint32_t material) {
    struct Face {
        glm::vec3 normal, right, up; // cross(right, up) == normal
    };
    static const Face faces[6] = {
        {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}, {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
        {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}}, {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
        {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},  {{0, 0, -1}, {-1, 0, 0}, {0, 1, 0}},
    };
    Mesh mesh;
    mesh.name = name;
    mesh.material = material;
    glm::vec3 half = size * 0.5f;
    for (const Face& f : faces) {
        glm::vec3 centre = f.normal * half;
        float hr = glm::dot(glm::abs(f.right), half), hu = glm::dot(glm::abs(f.up), half);
        uint32_t base = uint32_t(mesh.vertices.size());
        const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
        for (const auto& c : corners) {
            Vertex v{};
            v.position = centre + f.right * (hr * c[0]) + f.up * (hu * c[1]);
            v.normal = f.normal;
            v.uv0 = glm::vec2((c[0] + 1.0f) * hr, (c[1] + 1.0f) * hu);
            v.uv1 = v.uv0; // one UV set: the second is the first
            mesh.vertices.push_back(v);
        }
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) mesh.indices.push_back(base + i);
    }
    finishProceduralMesh(mesh);
    return mesh;
}

Mesh makePlane(const std::string& name, float sizeX, float sizeZ, uint32_t material,
               uint32_t subdivisions) {
    Mesh mesh;
    mesh.name = name;
    mesh.material = material;
    uint32_t n = std::max(1u, subdivisions);
    for (uint32_t j = 0; j <= n; ++j) {
        for (uint32_t i = 0; i <= n; ++i) {
            Vertex v{};
            v.position = {sizeX * (float(i) / float(n) - 0.5f), 0.0f,
                          sizeZ * (float(j) / float(n) - 0.5f)};
            v.normal = {0, 1, 0};
            v.uv0 = {v.position.x, -v.position.z};
            v.uv1 = v.uv0; // one UV set: the second is the first
            mesh.vertices.push_back(v);
        }
    }
    for (uint32_t j = 0; j < n; ++j) {
        for (uint32_t i = 0; i < n; ++i) {
            uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
            for (uint32_t k : {a, c, b, b, c, d}) mesh.indices.push_back(k);
        }
    }
    finishProceduralMesh(mesh);
    return mesh;
}

Mesh makeSphere(const std::string& name, float radius, uint32_t material, uint32_t segments,
                uint32_t rings) {
    Mesh mesh;
    mesh.name = name;
    mesh.material = material;
    segments = std::max(3u, segments);
    rings = std::max(2u, rings);
    const float pi = glm::pi<float>();
    for (uint32_t i = 0; i <= rings; ++i) {
        float theta = pi * float(i) / float(rings);
        for (uint32_t j = 0; j <= segments; ++j) {
            float phi = 2.0f * pi * float(j) / float(segments);
            glm::vec3 dir{std::sin(theta) * std::cos(phi), std::cos(theta),
                          -std::sin(theta) * std::sin(phi)};
            Vertex v{};
            v.position = dir * radius;
            v.normal = dir;
            v.uv0 = {phi * radius, theta * radius};
            v.uv1 = v.uv0; // one UV set: the second is the first
            mesh.vertices.push_back(v);
        }
    }
    const uint32_t row = segments + 1;
    for (uint32_t i = 0; i < rings; ++i) {
        for (uint32_t j = 0; j < segments; ++j) {
            uint32_t a = i * row + j, b = (i + 1) * row + j, c = b + 1, d = a + 1;
            // The pole rows collapse one of the quad's triangles to zero area: leave it out.
            if (i != rings - 1) mesh.indices.insert(mesh.indices.end(), {a, b, c});
            if (i != 0) mesh.indices.insert(mesh.indices.end(), {a, c, d});
        }
    }
    finishProceduralMesh(mesh);
    return mesh;
}

Mesh makeCylinder(const std::string& name, float radius, float height, uint32_t material,
                  uint32_t segments) {
    Mesh mesh;
    mesh.name = name;
    mesh.material = material;
    segments = std::max(3u, segments);
    const float pi = glm::pi<float>();
    // Side: a ring at the bottom and one at the top, with a seam column for the UV wrap.
    for (uint32_t ring = 0; ring < 2; ++ring) {
        for (uint32_t j = 0; j <= segments; ++j) {
            float phi = 2.0f * pi * float(j) / float(segments);
            glm::vec3 dir{std::cos(phi), 0.0f, -std::sin(phi)};
            Vertex v{};
            v.position = dir * radius + glm::vec3(0, ring * height, 0);
            v.normal = dir;
            v.uv0 = {phi * radius, ring * height};
            v.uv1 = v.uv0; // one UV set: the second is the first
            mesh.vertices.push_back(v);
        }
    }
    const uint32_t row = segments + 1;
    for (uint32_t j = 0; j < segments; ++j) {
        uint32_t a = j, b = j + 1, c = row + j, d = row + j + 1;
        mesh.indices.insert(mesh.indices.end(), {a, b, d, a, d, c});
    }
    // Caps: a centre vertex and their own ring so normals stay flat.
    for (uint32_t cap = 0; cap < 2; ++cap) {
        float y = cap * height;
        glm::vec3 normal{0, cap ? 1.0f : -1.0f, 0};
        uint32_t centre = uint32_t(mesh.vertices.size());
        Vertex c{};
        c.position = {0, y, 0};
        c.normal = normal;
        mesh.vertices.push_back(c);
        for (uint32_t j = 0; j < segments; ++j) {
            float phi = 2.0f * pi * float(j) / float(segments);
            Vertex v{};
            v.position = {radius * std::cos(phi), y, -radius * std::sin(phi)};
            v.normal = normal;
            v.uv0 = {v.position.x, cap ? -v.position.z : v.position.z};
            v.uv1 = v.uv0; // one UV set: the second is the first
            mesh.vertices.push_back(v);
        }
        for (uint32_t j = 0; j < segments; ++j) {
            uint32_t a = centre + 1 + j, b = centre + 1 + (j + 1) % segments;
            mesh.indices.insert(mesh.indices.end(), {centre, a, b});
        }
    }
    finishProceduralMesh(mesh);
    return mesh;
}

} // namespace shadel
