#include "bake/mesh_distance_field.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "bake/bake_cache.h"
#include "core/atomic_file.h"
#include "core/log.h"

namespace shadel {

namespace {

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
glm::vec3 closestOnTriangle(glm::vec3 p, glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    glm::vec3 ab = b - a, ac = c - a, ap = p - a;
    float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return a;
    glm::vec3 bp = p - b;
    float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return b;
    float vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
    glm::vec3 cp = p - c;
    float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return c;
    float vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
    float va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    float denom = 1.0f / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

// Whether the ray o + t d (t > 0) crosses triangle abc (Moller-Trumbore).
bool rayCrosses(glm::vec3 o, glm::vec3 d, glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    glm::vec3 e1 = b - a, e2 = c - a;
    glm::vec3 p = glm::cross(d, e2);
    float det = glm::dot(e1, p);
    if (std::abs(det) < 1e-12f) return false;
    float inv = 1.0f / det;
    glm::vec3 s = o - a;
    float u = glm::dot(s, p) * inv;
    if (u < 0 || u > 1) return false;
    glm::vec3 q = glm::cross(s, e1);
    float v = glm::dot(d, q) * inv;
    if (v < 0 || u + v > 1) return false;
    return glm::dot(e2, q) * inv > 0;
}

constexpr char kMagic[8] = {'S', 'H', 'D', 'L', 'M', 'S', 'D', 'F'};
constexpr uint32_t kFormatVersion = 1;

struct FileHeader {
    char magic[8];
    uint32_t version;
    uint32_t resolutionParam;
    uint64_t keyLo, keyHi;
    uint32_t res[3];
    float origin[3];
    float voxelSize;
    uint32_t pad;
    uint64_t checksum; // of the distances
};

BakeKey fieldKey(const Mesh& mesh, uint32_t resolution) {
    BakeSettings settings; // the mesh's content hash; the bake settings are only salt here
    BakeKey k = bakeKey(mesh, settings);
    k.lo = hashBytes(&resolution, sizeof resolution, k.lo ^ 0x5D1F5D1Full);
    k.hi = hashBytes(&kFormatVersion, sizeof kFormatVersion, k.hi ^ 0x5D1F5D1Full);
    return k;
}

bool readField(const std::string& path, const BakeKey& key, uint32_t resolution,
               MeshDistanceField& out) {
    uint64_t side = 4ull * resolution; // the largest field readField accepts
    std::vector<uint8_t> bytes;
    if (!readCacheEntry(path, sizeof(FileHeader) + side * side * side * sizeof(float), bytes)
             .empty())
        return false;
    FileHeader h;
    if (bytes.size() < sizeof h) return false;
    std::memcpy(&h, bytes.data(), sizeof h);
    if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0 || h.version != kFormatVersion ||
        h.resolutionParam != resolution || h.keyLo != key.lo || h.keyHi != key.hi)
        return false;
    uint64_t count = uint64_t(h.res[0]) * h.res[1] * h.res[2];
    if (h.res[0] == 0 || h.res[0] > 4 * resolution || h.res[1] > 4 * resolution ||
        h.res[2] > 4 * resolution || bytes.size() != sizeof h + count * sizeof(float))
        return false;
    const char* payload = reinterpret_cast<const char*>(bytes.data()) + sizeof h;
    if (hashBytes(payload, count * sizeof(float), 0) != h.checksum) return false;
    out.resolution = {h.res[0], h.res[1], h.res[2]};
    out.origin = {h.origin[0], h.origin[1], h.origin[2]};
    out.voxelSize = h.voxelSize;
    out.distances.resize(count);
    std::memcpy(out.distances.data(), payload, count * sizeof(float));
    return true;
}

} // namespace

MeshDistanceField buildMeshDistanceField(const Mesh& mesh, uint32_t resolution) {
    MeshDistanceField f;
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const Vertex& v : mesh.vertices)
        lo = glm::min(lo, v.position), hi = glm::max(hi, v.position);
    if (mesh.vertices.empty() || mesh.indices.size() < 3) return f;
    glm::vec3 extent = hi - lo;
    float longest = std::max({extent.x, extent.y, extent.z, 1e-4f});
    const uint32_t border = 2;
    f.voxelSize = longest / float(std::max(resolution, 4u) - 2 * border);
    for (int a = 0; a < 3; ++a)
        f.resolution[a] = uint32_t(std::ceil(extent[a] / f.voxelSize)) + 1 + 2 * border;
    f.origin = lo - glm::vec3(float(border) * f.voxelSize);
    f.distances.resize(size_t(f.resolution.x) * f.resolution.y * f.resolution.z);
    // Three rays off the axes (no edge is parallel to them in the built-in meshes).
    const glm::vec3 rays[3] = {glm::normalize(glm::vec3(1.0f, 0.113f, 0.071f)),
                               glm::normalize(glm::vec3(0.093f, 1.0f, 0.137f)),
                               glm::normalize(glm::vec3(0.061f, 0.089f, 1.0f))};
    const auto& idx = mesh.indices;
    size_t i = 0;
    for (uint32_t z = 0; z < f.resolution.z; ++z)
        for (uint32_t y = 0; y < f.resolution.y; ++y)
            for (uint32_t x = 0; x < f.resolution.x; ++x, ++i) {
                glm::vec3 p = f.origin + glm::vec3(x, y, z) * f.voxelSize;
                float best = 1e30f;
                int crossings[3] = {0, 0, 0};
                for (size_t t = 0; t + 2 < idx.size(); t += 3) {
                    glm::vec3 a = mesh.vertices[idx[t]].position;
                    glm::vec3 b = mesh.vertices[idx[t + 1]].position;
                    glm::vec3 c = mesh.vertices[idx[t + 2]].position;
                    glm::vec3 q = closestOnTriangle(p, a, b, c);
                    glm::vec3 dq = p - q;
                    best = std::min(best, glm::dot(dq, dq));
                    for (int r = 0; r < 3; ++r) crossings[r] += rayCrosses(p, rays[r], a, b, c);
                }
                int inside = (crossings[0] & 1) + (crossings[1] & 1) + (crossings[2] & 1);
                float d = std::sqrt(best);
                f.distances[i] = inside >= 2 ? -d : d;
            }
    return f;
}

MeshDistanceField loadOrBuildMeshDistanceField(const Mesh& mesh, const std::string& cacheDir,
                                               bool* fromCache, uint32_t resolution) {
    if (fromCache) *fromCache = false;
    std::string path;
    BakeKey key;
    if (!cacheDir.empty()) {
        key = fieldKey(mesh, resolution);
        path = (std::filesystem::path(cacheDir) / "sdf" / (key.hex() + ".sdf")).string();
        MeshDistanceField cached;
        if (readField(path, key, resolution, cached)) {
            if (fromCache) *fromCache = true;
            return cached;
        }
    }
    MeshDistanceField f = buildMeshDistanceField(mesh, resolution);
    if (!path.empty() && !f.distances.empty()) {
        FileHeader h{};
        std::memcpy(h.magic, kMagic, sizeof kMagic);
        h.version = kFormatVersion;
        h.resolutionParam = resolution;
        h.keyLo = key.lo, h.keyHi = key.hi;
        for (int a = 0; a < 3; ++a) h.res[a] = f.resolution[a], h.origin[a] = f.origin[a];
        h.voxelSize = f.voxelSize;
        h.checksum = hashBytes(f.distances.data(), f.distances.size() * sizeof(float), 0);
        std::vector<char> bytes(sizeof h + f.distances.size() * sizeof(float));
        std::memcpy(bytes.data(), &h, sizeof h);
        std::memcpy(bytes.data() + sizeof h, f.distances.data(),
                    f.distances.size() * sizeof(float));
        std::error_code ec;
        std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ec);
        std::string why = writeCacheEntry(path, bytes.data(), bytes.size());
        if (!why.empty()) SHADEL_WARN("distance field cache not written: %s", why.c_str());
    }
    return f;
}

} // namespace shadel
