#include "bake/bake_validate.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <unordered_map>

#include "bake/id_map.h"
#include "common/shadel_bary.h"
#include "core/log.h"

namespace shadel {
namespace {

constexpr uint32_t kNone = ~0u;

uint32_t findRoot(std::vector<uint32_t>& parent, uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
}

std::string checkStructure(const Mesh& mesh, const BakedMesh& b) {
    if (b.width == 0 || b.height == 0 || b.width % 8 || b.height % 8)
        return format("resolution %ux%u is not a positive multiple of 8", b.width, b.height);
    if (b.idMaps.size() != bakedMipCount(b.width, b.height))
        return format("%zu ID-map levels, expected %u", b.idMaps.size(),
                      bakedMipCount(b.width, b.height));
    for (size_t k = 0; k < b.idMaps.size(); ++k)
        if (b.idMaps[k].size() != size_t(b.width >> k) * (b.height >> k))
            return format("ID map %zu has %zu entries", k, b.idMaps[k].size());
    if (b.indices.size() != mesh.indices.size()) return "index count differs from the source";
    if (b.vertexRemap.size() != b.shadelUv.size()) return "remap and UV counts differ";
    for (uint32_t v : b.vertexRemap)
        if (v >= mesh.vertices.size()) return "vertex remap out of range";
    for (size_t i = 0; i < b.indices.size(); ++i) {
        if (b.indices[i] >= b.vertexRemap.size()) return "baked index out of range";
        if (b.vertexRemap[b.indices[i]] != mesh.indices[i])
            return format("baked corner %zu does not remap to its source vertex", i);
    }
    for (glm::vec2 uv : b.shadelUv)
        if (!(uv.x >= 0 && uv.x <= 1 && uv.y >= 0 && uv.y <= 1)) return "shadel UV outside [0,1]";
    for (const std::vector<uint16_t>& level : b.idMaps)
        for (uint16_t id : level)
            if (id != kEmptyShadel && id >= mesh.triangleCount()) return "triangle ID out of range";
    return {};
}

// Charts = connected regions in UV space: triangles joined by a shared baked vertex, or by
// baked vertices at the identical UV (seam duplicates of one surface point). Returns each
// triangle's chart (a representative baked vertex) and sets v.chartComponents.
std::vector<uint32_t> chartOfTriangles(const BakedMesh& b, uint32_t triangles, BakeValidation& v) {
    std::vector<uint32_t> parent(b.vertexRemap.size());
    std::iota(parent.begin(), parent.end(), 0u);
    std::unordered_map<uint64_t, uint32_t> byUv;
    for (uint32_t i = 0; i < b.shadelUv.size(); ++i) {
        uint32_t bits[2];
        std::memcpy(bits, &b.shadelUv[i], sizeof bits);
        auto [it, inserted] = byUv.emplace((uint64_t(bits[0]) << 32) | bits[1], i);
        if (!inserted) parent[findRoot(parent, i)] = findRoot(parent, it->second);
    }
    for (uint32_t t = 0; t < triangles; ++t)
        for (int c = 1; c < 3; ++c)
            parent[findRoot(parent, b.indices[3 * t + c])] = findRoot(parent, b.indices[3 * t]);
    std::vector<uint32_t> chartOf(triangles);
    for (uint32_t t = 0; t < triangles; ++t) chartOf[t] = findRoot(parent, b.indices[3 * t]);
    std::vector<uint32_t> roots(chartOf);
    std::sort(roots.begin(), roots.end());
    v.chartComponents = uint32_t(std::unique(roots.begin(), roots.end()) - roots.begin());

    return chartOf;
}

// The world-space area of every triangle (0 where it is not finite).
std::vector<double> triangleAreas(const Mesh& mesh, uint32_t triangles) {
    std::vector<double> worldArea(triangles);
    for (uint32_t t = 0; t < triangles; ++t) {
        glm::dvec3 p0 = mesh.vertices[mesh.indices[3 * t]].position;
        glm::dvec3 p1 = mesh.vertices[mesh.indices[3 * t + 1]].position;
        glm::dvec3 p2 = mesh.vertices[mesh.indices[3 * t + 2]].position;
        double a = 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
        worldArea[t] = std::isfinite(a) ? a : 0.0;
    }

    return worldArea;
}

// Overlaps and ownership at MIP 0.
void checkOverlaps(const BakedMesh& b, uint32_t triangles, const std::vector<uint32_t>& chartOf,
                   BakeValidation& v) {
    // Overlaps: standard coverage of every triangle at MIP 0, counting shadels claimed twice.
    size_t texels = size_t(b.width) * b.height;
    std::vector<uint32_t> claim(texels, kNone);
    std::vector<uint8_t> counted(texels, 0);
    forEachCoveredShadel(b.shadelUv, b.indices, b.width, b.height,
                         [&](uint32_t t, uint32_t x, uint32_t y) {
                             size_t p = size_t(y) * b.width + x;
                             if (claim[p] == kNone) {
                                 claim[p] = t;
                             } else if (!(counted[p] & 1)) {
                                 counted[p] |= 1;
                                 ++v.doubleCoveredShadels;
                                 if (chartOf[claim[p]] != chartOf[t]) ++v.crossChartShadels;
                             }
                         });

    std::vector<uint32_t> owned(triangles, 0);
    for (uint16_t id : b.idMaps[0])
        if (id != kEmptyShadel) ++owned[id];
    for (uint32_t t = 0; t < triangles; ++t) v.unownedTriangles += owned[t] == 0;
}

// Empty and foreign reads of the reconstruction filter, per level.
void countFilterReads(const BakedMesh& b, const std::vector<uint32_t>& chartOf,
                      const std::vector<double>& worldArea, BakeValidation& v) {
    // Reads of the reconstruction filter, per level: bilinear taps at points inside visible
    // triangles, namely each covered shadel centre pushed 0.49 shadel towards each of its eight
    // neighbours (kept if still inside the triangle), read the 2x2 shadels around the point.
    for (uint32_t k = 0; k < b.idMaps.size(); ++k) {
        uint32_t w = b.width >> k, h = b.height >> k;
        const std::vector<uint16_t>& ids = b.idMaps[k];
        uint64_t empty = 0, foreign = 0;
        forEachCoveredShadel(b.shadelUv, b.indices, w, h, [&](uint32_t t, uint32_t x, uint32_t y) {
            if (worldArea[t] <= 0) return;
            glm::dvec2 a = glm::dvec2(b.shadelUv[b.indices[3 * t]]) * glm::dvec2(w, h);
            glm::dvec2 e1 = glm::dvec2(b.shadelUv[b.indices[3 * t + 1]]) * glm::dvec2(w, h) - a;
            glm::dvec2 e2 = glm::dvec2(b.shadelUv[b.indices[3 * t + 2]]) * glm::dvec2(w, h) - a;
            double den = e1.x * e2.y - e2.x * e1.y;
            for (int dy = -1; dy <= 1; ++dy) {
                for (int dx = -1; dx <= 1; ++dx) {
                    glm::dvec2 p(x + 0.5 + 0.49 * dx, y + 0.5 + 0.49 * dy);
                    glm::dvec2 ap = p - a;
                    double wb = (ap.x * e2.y - e2.x * ap.y) / den,
                           wc = (e1.x * ap.y - ap.x * e1.y) / den;
                    if (!(wb >= 0 && wc >= 0 && wb + wc <= 1)) continue;
                    int64_t x0 = int64_t(std::floor(p.x - 0.5)),
                            y0 = int64_t(std::floor(p.y - 0.5));
                    for (int64_t ny = y0; ny <= y0 + 1; ++ny) {
                        for (int64_t nx = x0; nx <= x0 + 1; ++nx) {
                            // The renderer clamps taps to the rect (bake.h).
                            int64_t cx = std::clamp<int64_t>(nx, 0, w - 1),
                                    cy = std::clamp<int64_t>(ny, 0, h - 1);
                            uint16_t id = ids[size_t(cy) * w + size_t(cx)];
                            if (id == kEmptyShadel)
                                ++empty;
                            else if (chartOf[id] != chartOf[t])
                                ++foreign;
                        }
                    }
                }
            }
        });
        v.emptyReads.push_back(empty);
        v.foreignReads.push_back(foreign);
    }
}

// Shadel density over the mesh: area-weighted mean and coefficient of variation.
void measureDensity(const BakedMesh& b, uint32_t triangles, const std::vector<double>& worldArea,
                    BakeValidation& v) {
    // Density: shadels per m^2 of every triangle with area, weighted by area.
    double sumW = 0, sum = 0, sum2 = 0;
    for (uint32_t t = 0; t < triangles; ++t) {
        if (!(worldArea[t] > 1e-12)) continue;
        glm::dvec2 a = glm::dvec2(b.shadelUv[b.indices[3 * t]]) * glm::dvec2(b.width, b.height);
        glm::dvec2 e1 =
            glm::dvec2(b.shadelUv[b.indices[3 * t + 1]]) * glm::dvec2(b.width, b.height) - a;
        glm::dvec2 e2 =
            glm::dvec2(b.shadelUv[b.indices[3 * t + 2]]) * glm::dvec2(b.width, b.height) - a;
        double density = 0.5 * std::abs(e1.x * e2.y - e1.y * e2.x) / worldArea[t];
        sumW += worldArea[t], sum += worldArea[t] * density,
            sum2 += worldArea[t] * density * density;
    }
    if (sumW > 0) {
        v.densityMean = sum / sumW;
        double variance = std::max(0.0, sum2 / sumW - v.densityMean * v.densityMean);
        v.densityCv = v.densityMean > 0 ? std::sqrt(variance) / v.densityMean : 0;
    }
}

// Reconstruction error and neighbour spacing at MIP 0.
void checkReconstruction(const Mesh& mesh, const BakedMesh& b, const std::vector<double>& worldArea,
                         BakeValidation& v) {
    namespace sh = shader;
    // Reconstruction from ID shadel + clamped barycentrics (the GPU path, in float) against the
    // exact surface point mapped to the shadel centre (double).
    double shadelsPerMetre = b.shadelsPerMetre;
    // Float positions cannot be interpolated more exactly than a few ulps of their magnitude.
    double maxCoordinate = 0;
    for (const Vertex& vertex : mesh.vertices)
        for (int c = 0; c < 3; ++c)
            if (std::isfinite(vertex.position[c]))
                maxCoordinate = std::max(maxCoordinate, double(std::abs(vertex.position[c])));
    v.reconstructionTolerance =
        kMaxReconstructionError + 4.0 * std::ldexp(maxCoordinate, -23) * shadelsPerMetre;
    v.minNeighbourSpacing = 1e300;
    glm::uvec2 size(b.width, b.height);
    for (uint32_t y = 0; y < b.height; ++y) {
        for (uint32_t x = 0; x < b.width; ++x) {
            uint16_t t = b.idMaps[0][size_t(y) * b.width + x];
            if (t == kEmptyShadel || !(worldArea[t] > 1e-12)) continue;
            glm::vec2 uv[3];
            glm::vec3 pos[3];
            for (int c = 0; c < 3; ++c) {
                uint32_t bv = b.indices[3 * t + c];
                uv[c] = b.shadelUv[bv];
                pos[c] = mesh.vertices[b.vertexRemap[bv]].position;
            }
            auto exact = [&](uint32_t sx, uint32_t sy, glm::dvec3& out) {
                glm::dvec2 p((sx + 0.5) / b.width, (sy + 0.5) / b.height);
                glm::dvec2 a(uv[0]), e1 = glm::dvec2(uv[1]) - a, e2 = glm::dvec2(uv[2]) - a,
                                     ap = p - a;
                double den = e1.x * e2.y - e2.x * e1.y;
                if (den == 0) return false;
                double wb = (ap.x * e2.y - e2.x * ap.y) / den,
                       wc = (e1.x * ap.y - ap.x * e1.y) / den;
                double wa = 1 - wb - wc;
                out = wa * glm::dvec3(pos[0]) + wb * glm::dvec3(pos[1]) + wc * glm::dvec3(pos[2]);
                return wa >= 0 && wb >= 0 && wc >= 0;
            };
            glm::dvec3 reference;
            if (!exact(x, y, reference)) continue;
            glm::vec3 bary =
                sh::shadelBarycentrics(sh::shadelCenterUv({x, y}, size), uv[0], uv[1], uv[2]);
            glm::dvec3 rebuilt(sh::shadelInterpolate(bary, pos[0], pos[1], pos[2]));
            v.maxReconstructionError = std::max(v.maxReconstructionError,
                                                glm::length(rebuilt - reference) * shadelsPerMetre);
            ++v.reconstructedShadels;
            glm::dvec3 right;
            if (x + 1 < b.width && exact(x + 1, y, right)) {
                double spacing = glm::length(right - reference) * shadelsPerMetre;
                ++v.spacingPairs;
                v.minNeighbourSpacing = std::min(v.minNeighbourSpacing, spacing);
                v.maxNeighbourSpacing = std::max(v.maxNeighbourSpacing, spacing);
            }
        }
    }
    if (v.minNeighbourSpacing > v.maxNeighbourSpacing)
        v.minNeighbourSpacing = v.maxNeighbourSpacing = 0;
}

} // namespace

BakeValidation validateBake(const Mesh& mesh, const BakedMesh& b) {
    BakeValidation v;
    v.structureError = checkStructure(mesh, b);
    if (!v.structureError.empty()) return v;
    uint32_t triangles = mesh.triangleCount();
    std::vector<uint32_t> chartOf = chartOfTriangles(b, triangles, v);
    std::vector<double> worldArea = triangleAreas(mesh, triangles);
    checkOverlaps(b, triangles, chartOf, v);
    countFilterReads(b, chartOf, worldArea, v);
    measureDensity(b, triangles, worldArea, v);
    checkReconstruction(mesh, b, worldArea, v);
    return v;
}

std::string bakeViolation(const BakeValidation& v, const BakeSettings& settings) {
    if (!v.structureError.empty()) return "structure: " + v.structureError;
    if (v.crossChartShadels)
        return format("%llu shadels covered by two charts",
                      (unsigned long long)v.crossChartShadels);
    if (v.doubleCoveredShadels)
        return format("%llu shadels covered twice", (unsigned long long)v.doubleCoveredShadels);
    if (v.unownedTriangles) return format("%u triangles own no MIP-0 shadel", v.unownedTriangles);
    for (size_t k = 0; k < v.emptyReads.size(); ++k) {
        if (v.emptyReads[k])
            return format("MIP %zu: filter reads %llu empty shadels", k,
                          (unsigned long long)v.emptyReads[k]);
        if ((1u << k) <= settings.gutterShadels && v.foreignReads[k])
            return format("MIP %zu: filter reads %llu shadels of other charts", k,
                          (unsigned long long)v.foreignReads[k]);
    }
    if (v.densityCv > kMaxDensityCv)
        return format("density CV %.3f > %.3f", v.densityCv, kMaxDensityCv);
    if (v.maxReconstructionError > v.reconstructionTolerance)
        return format("reconstruction error %.4f shadels > %.4f", v.maxReconstructionError,
                      v.reconstructionTolerance);
    double maxStretch =
        1.0 / std::cos(glm::radians(std::min(double(settings.chartConeDegrees) + 10.0, 80.0)));
    if (v.spacingPairs &&
        (v.minNeighbourSpacing < 0.999 || v.maxNeighbourSpacing > maxStretch * 1.001))
        return format("shadel spacing %.3f .. %.3f outside 1 .. %.3f", v.minNeighbourSpacing,
                      v.maxNeighbourSpacing, maxStretch);
    return {};
}

} // namespace shadel
