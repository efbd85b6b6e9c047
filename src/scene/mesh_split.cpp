#include "scene/mesh_split.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <string>

#include "scene/mesh_utils.h"

namespace shadel {
namespace {

using Cell = glm::i64vec3;

// The vertices of the split mesh: the source's, then the new ones made on grid planes
// (deduplicated by their exact bits, so edges shared by two triangles share their new vertices).
struct VertexPool {
    std::vector<Vertex> vertices;
    std::map<std::array<uint32_t, 14>, uint32_t> made;

    uint32_t add(const Vertex& v) {
        static_assert(sizeof(Vertex) == 14 * sizeof(float));
        std::array<uint32_t, 14> key;
        std::memcpy(key.data(), &v, sizeof(Vertex));
        auto [it, inserted] = made.emplace(key, uint32_t(vertices.size()));
        if (inserted) vertices.push_back(v);
        return it->second;
    }

    // The point of edge (a, b) on the plane `axis` = value. Computed from the endpoints in a
    // canonical order, so both triangles sharing the edge get the same bits.
    float cell = 1.0f;

    uint32_t onPlane(uint32_t a, uint32_t b, int axis, float value) {
        const Vertex* p = &vertices[a];
        const Vertex* q = &vertices[b];
        auto less = [](const glm::vec3& x, const glm::vec3& y) {
            return x.x != y.x ? x.x < y.x : x.y != y.y ? x.y < y.y : x.z < y.z;
        };
        if (less(q->position, p->position)) std::swap(p, q);
        float t = (value - p->position[axis]) / (q->position[axis] - p->position[axis]);
        Vertex v;
        v.position = glm::mix(p->position, q->position, t);
        v.position[axis] = value;
        // An edge through a grid line (two planes meeting) must hit it exactly, or the next
        // axis's clip would cut a sliver off one side only (a T-junction of 1e-7 units).
        for (int other = 0; other < 3; ++other) {
            if (other == axis) continue;
            float snapped = float(std::round(double(v.position[other]) / cell) * cell);
            if (std::abs(v.position[other] - snapped) <= 1e-5f * cell) v.position[other] = snapped;
        }
        glm::vec3 n = glm::mix(p->normal, q->normal, t);
        v.normal = glm::length(n) > 1e-20f ? glm::normalize(n) : p->normal;
        glm::vec3 tangent = glm::mix(glm::vec3(p->tangent), glm::vec3(q->tangent), t);
        tangent -= v.normal * glm::dot(v.normal, tangent); // unit and perpendicular, as imported
        v.tangent = glm::vec4(glm::length(tangent) > 1e-20f ? glm::normalize(tangent)
                                                            : glm::vec3(p->tangent),
                              p->tangent.w);
        v.uv0 = glm::mix(p->uv0, q->uv0, t);
        v.uv1 = glm::mix(p->uv1, q->uv1, t);
        return add(v);
    }
};

using Polygon = std::vector<uint32_t>; // convex, in the source triangle's winding

// Splits a convex polygon by the plane `axis` = value into the parts below and above. Vertices
// on the plane belong to both; a new vertex is made only where an edge crosses strictly.
void splitPolygon(VertexPool& pool, const Polygon& poly, int axis, float value, Polygon& below,
                  Polygon& above) {
    below.clear(), above.clear();
    for (size_t i = 0; i < poly.size(); ++i) {
        uint32_t a = poly[i], b = poly[(i + 1) % poly.size()];
        float da = pool.vertices[a].position[axis] - value;
        float db = pool.vertices[b].position[axis] - value;
        if (da <= 0) below.push_back(a);
        if (da >= 0) above.push_back(a);
        if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
            uint32_t m = pool.onPlane(a, b, axis, value);
            below.push_back(m);
            above.push_back(m);
        }
    }
}

// Cell indices are offset by 2^40 so they are non-negative (octree nodes are then index >> level)
// while nodes stay aligned to the object-space grid.
constexpr int64_t kCellBias = int64_t(1) << 40;

Cell cellOf(glm::vec3 p, float cell) {
    return Cell(std::floor(double(p.x) / cell), std::floor(double(p.y) / cell),
                std::floor(double(p.z) / cell)) +
           kCellBias;
}

struct Piece {
    std::array<uint32_t, 3> v;
    Cell cell;
};

} // namespace

std::vector<Mesh> splitMeshOnGrid(const Mesh& mesh, float cell,
                                  const std::function<bool(const Aabb&)>& wholeNode) {
    if (!(cell > 0) || !mesh.bounds.valid() || mesh.triangleCount() == 0 || wholeNode(mesh.bounds))
        return {mesh};

    // 1. Clip every triangle at the grid planes strictly inside its extent.
    VertexPool pool;
    pool.vertices = mesh.vertices;
    pool.cell = cell;
    std::vector<Piece> pieces;
    pieces.reserve(mesh.triangleCount());
    std::vector<Polygon> current, next;
    Polygon below, above;
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        current.assign(1, Polygon{mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]});
        bool clipped = false;
        for (int axis = 0; axis < 3; ++axis) {
            next.clear();
            for (Polygon& poly : current) {
                float lo = 1e30f, hi = -1e30f;
                for (uint32_t v : poly) {
                    lo = std::min(lo, pool.vertices[v].position[axis]);
                    hi = std::max(hi, pool.vertices[v].position[axis]);
                }
                int64_t first = int64_t(std::floor(double(lo) / cell)) + 1;
                int64_t last = int64_t(std::ceil(double(hi) / cell)) - 1;
                Polygon rest = poly;
                for (int64_t k = first; k <= last; ++k) {
                    float value = float(double(k) * cell);
                    if (!(value > lo && value < hi)) continue;
                    splitPolygon(pool, rest, axis, value, below, above);
                    clipped = true;
                    if (below.size() >= 3) next.push_back(below);
                    rest = above;
                    if (rest.size() < 3) break;
                }
                if (rest.size() >= 3) next.push_back(rest);
            }
            current.swap(next);
        }
        if (!clipped) {
            glm::vec3 c = (pool.vertices[mesh.indices[t]].position +
                           pool.vertices[mesh.indices[t + 1]].position +
                           pool.vertices[mesh.indices[t + 2]].position) /
                          3.0f;
            pieces.push_back(
                {{mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]}, cellOf(c, cell)});
            continue;
        }
        for (const Polygon& poly : current) {
            glm::vec3 c(0.0f);
            for (uint32_t v : poly) c += pool.vertices[v].position;
            Cell pc = cellOf(c / float(poly.size()), cell);
            for (size_t i = 1; i + 1 < poly.size(); ++i) {
                glm::vec3 p0 = pool.vertices[poly[0]].position;
                glm::vec3 e = glm::cross(pool.vertices[poly[i]].position - p0,
                                         pool.vertices[poly[i + 1]].position - p0);
                if (e == glm::vec3(0.0f)) continue; // collinear: covers nothing
                pieces.push_back({{poly[0], poly[i], poly[i + 1]}, pc});
            }
        }
    }

    // 2. Group cells top-down over an octree of the grid.
    Cell lo = pieces.front().cell, hi = lo;
    for (const Piece& p : pieces) lo = glm::min(lo, p.cell), hi = glm::max(hi, p.cell);
    int rootLevel = 0;
    while (glm::any(glm::notEqual(lo >> int64_t(rootLevel), hi >> int64_t(rootLevel)))) ++rootLevel;

    std::vector<std::vector<uint32_t>> chunks; // piece indices per chunk
    std::vector<uint32_t> all(pieces.size());
    for (uint32_t i = 0; i < all.size(); ++i) all[i] = i;
    std::function<void(int, std::vector<uint32_t>&)> visit = [&](int level,
                                                                 std::vector<uint32_t>& ids) {
        if (ids.empty()) return;
        Aabb box;
        for (uint32_t i : ids)
            for (uint32_t v : pieces[i].v) box.extend(pool.vertices[v].position);
        bool tooMany = ids.size() > kMaxTrianglesPerMesh;
        if (level == 0 || (!tooMany && wholeNode(box))) {
            chunks.push_back(std::move(ids));
            return;
        }
        std::array<std::vector<uint32_t>, 8> children;
        for (uint32_t i : ids) {
            Cell c = (pieces[i].cell >> int64_t(level - 1)) & int64_t(1);
            children[size_t(c.x + 2 * c.y + 4 * c.z)].push_back(i);
        }
        ids.clear();
        ids.shrink_to_fit();
        for (auto& child : children) visit(level - 1, child);
    };
    visit(rootLevel, all);
    if (chunks.size() == 1 && pieces.size() == mesh.triangleCount()) {
        // Nothing was clipped and nothing split: keep the source mesh exactly.
        bool same = true;
        for (size_t i = 0; i < pieces.size() && same; ++i)
            for (int k = 0; k < 3; ++k) same &= pieces[i].v[k] == mesh.indices[i * 3 + k];
        if (same) return {mesh};
    }

    // 3. One compact mesh per chunk, triangles in source order.
    std::vector<Mesh> out;
    out.reserve(chunks.size());
    std::vector<uint32_t> remap(pool.vertices.size(), UINT32_MAX);
    for (size_t c = 0; c < chunks.size(); ++c) {
        std::vector<uint32_t>& ids = chunks[c];
        std::sort(ids.begin(), ids.end());
        Mesh m;
        m.name = mesh.name + " chunk " + std::to_string(c);
        m.material = mesh.material;
        std::vector<uint32_t> used;
        for (uint32_t i : ids)
            for (uint32_t v : pieces[i].v) {
                if (remap[v] == UINT32_MAX) {
                    remap[v] = uint32_t(m.vertices.size());
                    m.vertices.push_back(pool.vertices[v]);
                    used.push_back(v);
                }
                m.indices.push_back(remap[v]);
            }
        for (uint32_t v : used) remap[v] = UINT32_MAX;
        computeBounds(m);
        out.push_back(std::move(m));
    }
    return out;
}

} // namespace shadel
