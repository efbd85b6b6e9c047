#include "bake/charting.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <unordered_map>

#include "bake/arap.h"
#include "bake/lscm.h"
#include "bake/stretch.h"
#include "core/error.h"
#include "core/log.h"

namespace shadel {
namespace {

constexpr uint32_t kNone = ~0u;
constexpr uint32_t kOutside = ~0u - 1; // growCharts: triangle not in the subset being grown
// A chart filling less than this fraction of its bounding rectangle is cut in two.
constexpr double kMinRectFill = 0.5;
constexpr size_t kMinTrianglesToSplitForFill = 8;
// ... and only if its halves' rectangles together are smaller than this fraction of its own.
constexpr double kMinSplitGain = 0.8;
// Charts of at most this many triangles try to merge into a neighbour after growth.
constexpr size_t kSmallChartTriangles = 16;
// Charts grow over a wider normal cone than planar projection could take: a conformal map unrolls
// curved patches that a projection would squash. The stretch check decides what is kept, so the
// cone only has to keep charts far from closing on themselves. Growth first tries the wide cone
// (fewer, bigger charts on smooth curved surfaces); a wide chart that does not flatten is grown
// again with the narrow one within its own triangles before any cutting in halves (halves of a
// wide chart are worse charts than narrow growth makes).
constexpr double kConformalExtraConeDegrees = 25;
constexpr double kWideConformalExtraConeDegrees = 35;
constexpr double kMaxGrowthConeDegrees = 75;
// Conformal charts are accepted up to the planar stretch bound (1/cos(cone + 10), what
// bake_validate.h checks), with a margin, and while their density stays within a deviation of the
// requested one (ChartDistortion::densityDeviation). kSafeChartDensityDeviation = 0.16 bounds the
// mesh's density coefficient of variation by 0.16 / 0.84 = 0.19 <= 0.2 whatever the charts; the
// first attempt allows kLooseChartDensityDeviation per chart (bigger charts, less gutter) and is
// kept only if the mesh's CV, measured over all charts, stays within kMaxMeshDensityCv; else the
// mesh is charted again with the safe bound.
constexpr double kStretchMargin = 0.99;
constexpr double kSafeChartDensityDeviation = 0.16;
constexpr double kLooseChartDensityDeviation = 0.2;
// Below bake_validate.h's 0.2: UVs are rounded to float and chart placement to shadels.
constexpr double kMaxMeshDensityCv = 0.18;
// Local/global iterations of the ARAP rescue (arap.h); it converges fast from an LSCM start.
constexpr int kArapIterations = 8;

struct TriangleInfo {
    glm::dvec3 normal{0.0};
    double area = 0;
    bool degenerate = true;
};

struct CellKey {
    int64_t x, y, z;
    bool operator==(const CellKey&) const = default;
};
struct CellKeyHash {
    size_t operator()(const CellKey& k) const {
        uint64_t h = uint64_t(k.x) * 0x9E3779B97F4A7C15ull;
        h ^= (h >> 29) + uint64_t(k.y) * 0xBF58476D1CE4E5B9ull;
        h ^= (h >> 31) + uint64_t(k.z) * 0x94D049BB133111EBull;
        return size_t(h ^ (h >> 32));
    }
};

// Source meshes split vertices along normal/UV seams, and their seam positions often differ in
// the last bits (sin(2 pi) != sin(0)). Charts must grow across those seams, so adjacency is built
// on positions welded within 1e-6 of the mesh size (first vertex within reach wins: order
// deterministic). Non-finite positions are never welded.
std::vector<uint32_t> weldPositions(const Mesh& mesh, std::vector<glm::dvec3>& representative) {
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const Vertex& v : mesh.vertices) {
        glm::dvec3 p(v.position);
        if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))
            lo = glm::min(lo, p), hi = glm::max(hi, p);
    }
    double eps = lo.x <= hi.x ? std::max(1e-6 * glm::length(hi - lo), 1e-12) : 1.0;
    std::unordered_map<CellKey, uint32_t, CellKeyHash> firstInCell;
    std::vector<uint32_t> nextInCell; // chains of representatives sharing a cell
    firstInCell.reserve(mesh.vertices.size());
    std::vector<uint32_t> weld(mesh.vertices.size());
    representative.clear();
    for (size_t v = 0; v < mesh.vertices.size(); ++v) {
        glm::dvec3 p(mesh.vertices[v].position);
        if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) ||
            std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) / eps > 1e15) {
            weld[v] = uint32_t(representative.size());
            representative.push_back(p);
            nextInCell.push_back(kNone);
            continue;
        }
        CellKey cell{int64_t(std::floor(p.x / eps)), int64_t(std::floor(p.y / eps)),
                     int64_t(std::floor(p.z / eps))};
        uint32_t found = kNone;
        for (int dz = -1; dz <= 1 && found == kNone; ++dz)
            for (int dy = -1; dy <= 1 && found == kNone; ++dy)
                for (int dx = -1; dx <= 1 && found == kNone; ++dx) {
                    auto it = firstInCell.find({cell.x + dx, cell.y + dy, cell.z + dz});
                    if (it == firstInCell.end()) continue;
                    for (uint32_t r = it->second; r != kNone; r = nextInCell[r]) {
                        glm::dvec3 d = glm::abs(representative[r] - p);
                        if (std::max({d.x, d.y, d.z}) <= eps) {
                            found = r;
                            break;
                        }
                    }
                }
        if (found == kNone) {
            found = uint32_t(representative.size());
            representative.push_back(p);
            auto [it, inserted] = firstInCell.emplace(cell, found);
            nextInCell.push_back(inserted ? kNone : it->second);
            if (!inserted) it->second = found;
        }
        weld[v] = found;
    }
    return weld;
}

// neighbour[3t+e] is the triangle across edge e (corner e -> e+1) of t, or kNone. Only manifold
// edges (exactly two non-degenerate triangles) connect: non-manifold edges become chart borders.
std::vector<uint32_t> buildNeighbours(const std::vector<uint32_t>& indices,
                                      const std::vector<uint32_t>& weld,
                                      const std::vector<TriangleInfo>& tris) {
    std::vector<std::pair<uint64_t, uint32_t>> edges;
    edges.reserve(indices.size());
    for (uint32_t t = 0; t < tris.size(); ++t) {
        if (tris[t].degenerate) continue;
        for (uint32_t e = 0; e < 3; ++e) {
            uint32_t a = weld[indices[3 * t + e]], b = weld[indices[3 * t + (e + 1) % 3]];
            uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
            edges.emplace_back(key, 3 * t + e);
        }
    }
    std::sort(edges.begin(), edges.end());
    std::vector<uint32_t> neighbour(indices.size(), kNone);
    for (size_t i = 0; i < edges.size();) {
        size_t j = i;
        while (j < edges.size() && edges[j].first == edges[i].first) ++j;
        if (j - i == 2) {
            neighbour[edges[i].second] = edges[i + 1].second / 3;
            neighbour[edges[i + 1].second] = edges[i].second / 3;
        }
        i = j;
    }
    return neighbour;
}

// Orthonormal u, v with u x v = n, so triangles facing n project counter-clockwise.
void planeBasis(glm::dvec3 n, glm::dvec3& u, glm::dvec3& v) {
    glm::dvec3 helper = std::abs(n.x) < 0.6   ? glm::dvec3(1, 0, 0)
                        : std::abs(n.y) < 0.6 ? glm::dvec3(0, 1, 0)
                                              : glm::dvec3(0, 0, 1);
    u = glm::normalize(glm::cross(helper, n));
    v = glm::cross(n, u);
}

// Strict 2-D overlap of two triangles (separating-axis test over the six edge normals). Shared
// edges and vertices only touch, which the tolerance accepts as separated.
bool trianglesOverlap(const glm::dvec2* a, const glm::dvec2* b, double tolerance) {
    const glm::dvec2* polys[2] = {a, b};
    for (const glm::dvec2* poly : polys) {
        for (int i = 0; i < 3; ++i) {
            glm::dvec2 d = poly[(i + 1) % 3] - poly[i];
            double len = glm::length(d);
            if (!(len > 0)) continue;
            glm::dvec2 axis(-d.y / len, d.x / len);
            double minA = 1e300, maxA = -1e300, minB = 1e300, maxB = -1e300;
            for (int k = 0; k < 3; ++k) {
                double pa = glm::dot(axis, a[k]), pb = glm::dot(axis, b[k]);
                minA = std::min(minA, pa), maxA = std::max(maxA, pa);
                minB = std::min(minB, pb), maxB = std::max(maxB, pb);
            }
            if (maxA <= minB + tolerance || maxB <= minA + tolerance) return false;
        }
    }
    return true;
}

// True if two triangles of a flattened piece overlap. Expected O(n) with a uniform grid over the
// triangles' bounding boxes. A pathological cell (thousands of triangles on one spot) exhausts
// the pair budget and reports an overlap, which only makes the caller split the piece: safe.
bool pieceSelfOverlaps(const std::vector<glm::dvec2>& corners) {
    size_t n = corners.size() / 3;
    if (n < 2) return false;
    glm::dvec2 lo(1e300), hi(-1e300);
    for (const glm::dvec2& c : corners) lo = glm::min(lo, c), hi = glm::max(hi, c);
    glm::dvec2 size = glm::max(hi - lo, glm::dvec2(1e-12));
    double cell = std::sqrt(size.x * size.y / double(n)) * 1.5;
    cell = std::max({cell, size.x / 1024.0, size.y / 1024.0});
    int gx = std::max(1, int(std::ceil(size.x / cell))),
        gy = std::max(1, int(std::ceil(size.y / cell)));
    // Welded seams are exact; the tolerance only absorbs rounding in the SAT projections.
    double tolerance = 1e-7 * std::max(size.x, size.y);

    std::vector<std::pair<uint32_t, uint32_t>> entries; // (cell, triangle)
    entries.reserve(n * 2);
    for (uint32_t t = 0; t < n; ++t) {
        glm::dvec2 tlo = glm::min(corners[3 * t], glm::min(corners[3 * t + 1], corners[3 * t + 2]));
        glm::dvec2 thi = glm::max(corners[3 * t], glm::max(corners[3 * t + 1], corners[3 * t + 2]));
        int x0 = std::clamp(int((tlo.x - lo.x) / cell), 0, gx - 1);
        int x1 = std::clamp(int((thi.x - lo.x) / cell), 0, gx - 1);
        int y0 = std::clamp(int((tlo.y - lo.y) / cell), 0, gy - 1);
        int y1 = std::clamp(int((thi.y - lo.y) / cell), 0, gy - 1);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) entries.emplace_back(uint32_t(y * gx + x), t);
    }
    std::sort(entries.begin(), entries.end());
    uint64_t budget = 20'000'000;
    for (size_t i = 0; i < entries.size();) {
        size_t j = i;
        while (j < entries.size() && entries[j].first == entries[i].first) ++j;
        for (size_t p = i; p < j; ++p) {
            for (size_t q = p + 1; q < j; ++q) {
                if (budget-- == 0) return true;
                if (trianglesOverlap(&corners[3 * entries[p].second],
                                     &corners[3 * entries[q].second], tolerance))
                    return true;
            }
        }
        i = j;
    }
    return false;
}

std::vector<glm::dvec2> convexHull(std::vector<glm::dvec2> pts) {
    std::sort(pts.begin(), pts.end(),
              [](glm::dvec2 a, glm::dvec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    if (pts.size() < 3) return pts;
    auto cross = [](glm::dvec2 o, glm::dvec2 a, glm::dvec2 b) {
        return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
    };
    std::vector<glm::dvec2> hull(2 * pts.size());
    size_t k = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
        while (k >= 2 && cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
        hull[k++] = pts[i];
    }
    for (size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {
        while (k >= t && cross(hull[k - 2], hull[k - 1], pts[i - 1]) <= 0) --k;
        hull[k++] = pts[i - 1];
    }
    hull.resize(k - 1);
    return hull;
}

struct MinAreaRect {
    glm::dvec2 direction{1, 0}; // of one side
    double area = 0;
};

// Rotating calipers over the convex hull: the minimum-area rectangle has a side on a hull edge.
MinAreaRect minAreaRect(const std::vector<glm::dvec2>& points) {
    std::vector<glm::dvec2> hull = convexHull(points);
    MinAreaRect best;
    best.area = 1e300;
    for (size_t i = 0; i < hull.size(); ++i) {
        glm::dvec2 d = hull[(i + 1) % hull.size()] - hull[i];
        double len = glm::length(d);
        if (!(len > 0)) continue;
        d /= len;
        glm::dvec2 p(-d.y, d.x);
        double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
        for (glm::dvec2 h : hull) {
            double a = glm::dot(h, d), b = glm::dot(h, p);
            x0 = std::min(x0, a), x1 = std::max(x1, a), y0 = std::min(y0, b), y1 = std::max(y1, b);
        }
        double area = (x1 - x0) * (y1 - y0);
        if (area < best.area - 1e-12 * std::abs(best.area)) best.area = area, best.direction = d;
    }
    if (best.area == 1e300) best.area = 0;
    return best;
}

// Rotates coords (in place) so their minimum-area bounding rectangle is axis-aligned with the
// longer side along x, and translates the minimum to the origin. Returns the extent.
glm::dvec2 alignToMinAreaRect(std::vector<glm::dvec2>& coords) {
    glm::dvec2 bestDir = minAreaRect(coords).direction;
    glm::dvec2 perp(-bestDir.y, bestDir.x); // (bestDir, perp) is a rotation: keeps orientation
    glm::dvec2 lo(1e300), hi(-1e300);
    for (glm::dvec2& c : coords) {
        c = glm::dvec2(glm::dot(c, bestDir), glm::dot(c, perp));
        lo = glm::min(lo, c), hi = glm::max(hi, c);
    }
    glm::dvec2 extent = hi - lo;
    bool turn = extent.x < extent.y;
    for (glm::dvec2& c : coords) {
        c -= lo;
        if (turn) c = glm::dvec2(c.y, extent.x - c.x); // quarter turn, still a rotation
    }
    return turn ? glm::dvec2(extent.y, extent.x) : extent;
}

class Charter {
public:
    Charter(const Mesh& mesh, const ChartingSettings& settings, double maxChartDensityDeviation)
        : mesh_(mesh), maxChartDensityDeviation_(maxChartDensityDeviation) {
        double cone = double(settings.coneDegrees);
        narrowGrowth_ = std::min(cone + kConformalExtraConeDegrees, kMaxGrowthConeDegrees);
        wideGrowth_ = settings.wideGrowthDegrees > 0
                          ? double(settings.wideGrowthDegrees)
                          : std::min(cone + kWideConformalExtraConeDegrees, kMaxGrowthConeDegrees);
        // Merging only absorbs slivers left between charts; across creases (box edges) it would
        // make folded nets that pack worse than their faces, so it keeps the planar bound.
        mergeLimit_ = glm::radians(std::min(cone + 5.0, 75.0));
        cosPlanar_ = std::cos(glm::radians(std::min(cone + 10.0, 80.0)));
        maxConformalStretch_ = kStretchMargin / cosPlanar_;
    }

    ChartedMesh run();

private:
    // Corner position, welded: seam duplicates project to identical chart coordinates.
    glm::dvec3 position(uint32_t t, uint32_t corner) const {
        return weldPosition_[weld_[mesh_.indices[3 * t + corner]]];
    }
    void classifyTriangles();
    // Charts grown over `subset` (non-degenerate triangles) within a cone of growthDegrees.
    std::vector<std::vector<uint32_t>> growCharts(std::vector<uint32_t> subset,
                                                  double growthDegrees);
    void mergeSmallCharts(std::vector<std::vector<uint32_t>>& charts,
                          std::vector<uint32_t>& chartOf);
    std::vector<std::vector<uint32_t>> connectedPieces(const std::vector<uint32_t>& tris);
    // A flattened piece, accepted as a chart.
    struct Flattened {
        std::vector<uint32_t> tris;
        std::vector<glm::dvec2> corners;
        ChartKind kind = ChartKind::Conformal;
        ChartDistortion distortion;
    };
    void flattenPieces(std::vector<std::vector<uint32_t>> work, std::vector<Flattened>& charts);
    void chartPiece(std::vector<uint32_t> piece, bool wide);
    bool flattenConformal(const std::vector<uint32_t>& tris, std::vector<glm::dvec2>& corners,
                          ChartDistortion& distortion);
    bool flattenPlanar(const std::vector<uint32_t>& tris, std::vector<glm::dvec2>& corners,
                       ChartDistortion& distortion);
    std::vector<glm::dvec3> surfaceCorners(const std::vector<uint32_t>& tris) const;
    double subsetRectArea(const std::vector<uint32_t>& subset,
                          const std::vector<glm::dvec2>& corners);
    void splitInHalves(const std::vector<uint32_t>& tris, std::vector<uint32_t>& lower,
                       std::vector<uint32_t>& upper) const;
    void emitChart(const std::vector<uint32_t>& tris, const std::vector<glm::dvec2>& corners,
                   ChartKind kind, const ChartDistortion& distortion);
    void emitDegenerateCells();

    const Mesh& mesh_;
    double maxChartDensityDeviation_;
    double narrowGrowth_, wideGrowth_; // growth cones, degrees
    double mergeLimit_;                // radians
    std::vector<uint32_t> chartOf_;    // per triangle, scratch of growCharts
    double cosPlanar_;                 // planar charts: every normal within this of the axis
    double maxConformalStretch_;
    std::vector<uint32_t> weld_;
    std::vector<glm::dvec3> weldPosition_;
    std::vector<TriangleInfo> tris_;
    std::vector<uint32_t> neighbour_;
    std::vector<uint32_t> stamp_; // per triangle, scratch membership marks
    uint32_t stampValue_ = 0;
    std::vector<uint32_t> localOf_;     // per welded vertex, scratch: its index in a patch
    std::vector<uint32_t> slotOf_;      // per triangle, scratch: its index in the piece flattened
    std::vector<uint32_t> vertexStamp_; // per source vertex: chart index + 1 that baked it
    std::vector<uint32_t> vertexBaked_; // per source vertex: its baked vertex in that chart
    ChartedMesh out_;
};

void Charter::classifyTriangles() {
    uint32_t n = mesh_.triangleCount();
    tris_.assign(n, {});
    for (uint32_t t = 0; t < n; ++t) {
        const uint32_t* idx = &mesh_.indices[3 * t];
        glm::dvec3 p0 = position(t, 0), p1 = position(t, 1), p2 = position(t, 2);
        glm::dvec3 cross = glm::cross(p1 - p0, p2 - p0);
        double len = glm::length(cross);
        double maxEdge2 = std::max(
            {glm::dot(p1 - p0, p1 - p0), glm::dot(p2 - p1, p2 - p1), glm::dot(p0 - p2, p0 - p2)});
        TriangleInfo& info = tris_[t];
        bool sharedCorner = weld_[idx[0]] == weld_[idx[1]] || weld_[idx[1]] == weld_[idx[2]] ||
                            weld_[idx[2]] == weld_[idx[0]];
        // Needles (sin of the smallest angle ~ 0), specks and non-finite positions are
        // "degenerate": they can never cover a pixel, so they get a private cell instead of a
        // place in a chart where they would only steal shadels from real triangles.
        info.degenerate = sharedCorner || !std::isfinite(len) || !std::isfinite(maxEdge2) ||
                          !(len > 1e-10 * maxEdge2) || !(len > 2e-14);
        if (!info.degenerate) {
            info.normal = cross / len;
            info.area = 0.5 * len;
            out_.surfaceArea += info.area;
        }
    }
}

std::vector<std::vector<uint32_t>> Charter::growCharts(std::vector<uint32_t> pending,
                                                       double growthDegrees) {
    double cosCone = std::cos(glm::radians(growthDegrees));
    double cosKeep = std::cos(glm::radians(growthDegrees + 10.0));
    // Seed from the largest triangles so big flat regions become big charts.
    std::stable_sort(pending.begin(), pending.end(),
                     [&](uint32_t a, uint32_t b) { return tris_[a].area > tris_[b].area; });
    // Triangles outside the subset stay kOutside, so growth never enters them.
    std::vector<uint32_t>& chartOf = chartOf_;
    for (uint32_t t : pending) chartOf[t] = kNone;
    std::vector<std::vector<uint32_t>> charts;
    std::vector<uint32_t> members;
    std::vector<std::pair<double, uint32_t>> frontier; // max-heap on alignment with the mean
    while (!pending.empty()) {
        std::vector<uint32_t> retry;
        for (uint32_t seed : pending) {
            if (chartOf[seed] != kNone) continue;
            uint32_t id = uint32_t(charts.size());
            glm::dvec3 sum = tris_[seed].normal * tris_[seed].area;
            members.assign(1, seed);
            chartOf[seed] = id;
            // Best-aligned neighbour first, so charts grow round and stop evenly at the cone.
            frontier.clear();
            auto pushNeighbours = [&](uint32_t t) {
                glm::dvec3 mean = glm::normalize(sum);
                for (uint32_t e = 0; e < 3; ++e) {
                    uint32_t u = neighbour_[3 * t + e];
                    if (u == kNone || chartOf[u] != kNone) continue;
                    frontier.push_back({glm::dot(tris_[u].normal, mean), u});
                    std::push_heap(frontier.begin(), frontier.end());
                }
            };
            pushNeighbours(seed);
            while (!frontier.empty()) {
                std::pop_heap(frontier.begin(), frontier.end());
                uint32_t u = frontier.back().second;
                frontier.pop_back();
                if (chartOf[u] != kNone) continue;
                glm::dvec3 nu = tris_[u].normal;
                if (glm::dot(nu, glm::normalize(sum)) < cosCone) continue;
                chartOf[u] = id;
                members.push_back(u);
                sum += nu * tris_[u].area;
                pushNeighbours(u);
            }
            // The mean normal drifts while growing; triangles that ended up far from the final
            // projection axis would be squashed, so they start charts of their own.
            glm::dvec3 axis = glm::normalize(sum);
            std::vector<uint32_t> kept;
            kept.reserve(members.size());
            for (uint32_t t : members) {
                if (t == seed || glm::dot(tris_[t].normal, axis) >= cosKeep) {
                    kept.push_back(t);
                } else {
                    chartOf[t] = kNone;
                    retry.push_back(t);
                }
            }
            charts.push_back(std::move(kept));
        }
        pending = std::move(retry);
    }
    mergeSmallCharts(charts, chartOf);
    for (const std::vector<uint32_t>& chart : charts)
        for (uint32_t t : chart) chartOf[t] = kOutside;
    return charts;
}

// Growth leaves slivers of triangles between charts that each stopped at the cone. Every small
// chart joins the neighbouring chart whose merged mean normal keeps every triangle of both
// within cone + 5 degrees: fewer charts, less gutter, still inside the stretch bound (cone + 10).
// Each chart tracks an upper bound of its triangles' angle to its mean normal, raised by the
// axis shift of every merge, so checking a merge never rescans a big chart.
void Charter::mergeSmallCharts(std::vector<std::vector<uint32_t>>& charts,
                               std::vector<uint32_t>& chartOf) {
    auto angle = [](glm::dvec3 a, glm::dvec3 b) {
        return std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
    };
    size_t count = charts.size();
    std::vector<glm::dvec3> sums(count, glm::dvec3(0.0)), axes(count);
    std::vector<double> areas(count, 0.0), maxAngle(count, 0.0);
    for (size_t c = 0; c < count; ++c) {
        for (uint32_t t : charts[c])
            sums[c] += tris_[t].normal * tris_[t].area, areas[c] += tris_[t].area;
        axes[c] = glm::normalize(sums[c]);
        for (uint32_t t : charts[c])
            maxAngle[c] = std::max(maxAngle[c], angle(tris_[t].normal, axes[c]));
    }
    std::vector<uint32_t> small;
    for (uint32_t c = 0; c < count; ++c)
        if (charts[c].size() <= kSmallChartTriangles) small.push_back(c);
    std::stable_sort(small.begin(), small.end(),
                     [&](uint32_t a, uint32_t b) { return areas[a] < areas[b]; });
    for (uint32_t s : small) {
        if (charts[s].empty()) continue;
        uint32_t best = kNone;
        double bestBound = mergeLimit_;
        glm::dvec3 bestAxis(0.0);
        for (uint32_t t : charts[s]) {
            for (uint32_t e = 0; e < 3; ++e) {
                uint32_t u = neighbour_[3 * t + e];
                if (u == kNone || chartOf[u] == kOutside || chartOf[u] == s || chartOf[u] == best)
                    continue;
                uint32_t c = chartOf[u];
                glm::dvec3 merged = sums[c] + sums[s];
                if (!(glm::length(merged) > 0)) continue;
                glm::dvec3 axis = glm::normalize(merged);
                double bound = maxAngle[c] + angle(axes[c], axis);
                for (uint32_t st : charts[s])
                    bound = std::max(bound, angle(tris_[st].normal, axis));
                if (bound <= bestBound) bestBound = bound, best = c, bestAxis = axis;
            }
        }
        if (best == kNone) continue;
        for (uint32_t t : charts[s]) chartOf[t] = best;
        charts[best].insert(charts[best].end(), charts[s].begin(), charts[s].end());
        charts[s].clear();
        sums[best] += sums[s], areas[best] += areas[s];
        axes[best] = bestAxis, maxAngle[best] = bestBound;
    }
    charts.erase(
        std::remove_if(charts.begin(), charts.end(), [](const auto& c) { return c.empty(); }),
        charts.end());
}

std::vector<std::vector<uint32_t>> Charter::connectedPieces(const std::vector<uint32_t>& tris) {
    uint32_t member = ++stampValue_;
    for (uint32_t t : tris) stamp_[t] = member;
    uint32_t visited = ++stampValue_;
    std::vector<std::vector<uint32_t>> pieces;
    for (uint32_t start : tris) {
        if (stamp_[start] != member) continue;
        std::vector<uint32_t> piece{start};
        stamp_[start] = visited;
        for (size_t head = 0; head < piece.size(); ++head) {
            for (uint32_t e = 0; e < 3; ++e) {
                uint32_t u = neighbour_[3 * piece[head] + e];
                if (u != kNone && stamp_[u] == member) {
                    stamp_[u] = visited;
                    piece.push_back(u);
                }
            }
        }
        pieces.push_back(std::move(piece));
    }
    return pieces;
}

std::vector<glm::dvec3> Charter::surfaceCorners(const std::vector<uint32_t>& tris) const {
    std::vector<glm::dvec3> surface(tris.size() * 3);
    for (size_t i = 0; i < tris.size(); ++i)
        for (uint32_t c = 0; c < 3; ++c) surface[3 * i + c] = position(tris[i], c);
    return surface;
}

// LSCM of a connected piece, on welded vertices so seam duplicates get one coordinate. Accepted
// when no triangle folds, the stretch is within bounds and the piece does not overlap itself;
// the corners are then scaled by 1 / maxSigma so the map never magnifies.
bool Charter::flattenConformal(const std::vector<uint32_t>& tris, std::vector<glm::dvec2>& corners,
                               ChartDistortion& distortion) {
    std::vector<glm::dvec3> positions;
    std::vector<uint32_t> triangles(tris.size() * 3);
    std::vector<uint32_t> welded;
    for (size_t i = 0; i < tris.size(); ++i) {
        for (uint32_t c = 0; c < 3; ++c) {
            uint32_t w = weld_[mesh_.indices[3 * tris[i] + c]];
            if (localOf_[w] == kNone) {
                localOf_[w] = uint32_t(positions.size());
                positions.push_back(weldPosition_[w]);
                welded.push_back(w);
            }
            triangles[3 * i + c] = localOf_[w];
        }
    }
    for (uint32_t w : welded) localOf_[w] = kNone;
    std::vector<glm::dvec2> uv;
    if (!lscmFlatten(positions, triangles, uv)) return false;
    // The solve is free to return the mirror image (triangles clockwise); mirror it back.
    double signedArea = 0;
    for (size_t k = 0; k < triangles.size(); k += 3) {
        glm::dvec2 e1 = uv[triangles[k + 1]] - uv[triangles[k]];
        glm::dvec2 e2 = uv[triangles[k + 2]] - uv[triangles[k]];
        signedArea += e1.x * e2.y - e1.y * e2.x;
    }
    if (signedArea < 0)
        for (glm::dvec2& q : uv) q.x = -q.x;
    std::vector<glm::dvec3> surface = surfaceCorners(tris);
    auto measure = [&](const std::vector<glm::dvec2>& flat) {
        corners.resize(triangles.size());
        for (size_t k = 0; k < triangles.size(); ++k) corners[k] = flat[triangles[k]];
        distortion = measureDistortion(surface, corners);
        return distortion.flippedTriangles == 0 && distortion.maxSigma > 0 &&
               distortion.maxStretch() <= maxConformalStretch_ &&
               distortion.densityDeviation() <= maxChartDensityDeviation_;
    };
    if (!measure(uv)) {
        // Too much scale drift for a conformal map: as-rigid-as-possible trades it for mild
        // anisotropy, which often brings a curved chart within bounds without cutting it.
        if (!arapRefine(positions, triangles, uv, kArapIterations) || !measure(uv)) return false;
    }
    double scale = 1.0 / distortion.maxSigma;
    for (glm::dvec2& c : corners) c *= scale;
    return !pieceSelfOverlaps(corners);
}

// Projection on the plane of the piece's mean normal: cannot fold for triangles facing the axis
// (all within cosPlanar_), but can still overlap globally (a ramp that spirals).
bool Charter::flattenPlanar(const std::vector<uint32_t>& tris, std::vector<glm::dvec2>& corners,
                            ChartDistortion& distortion) {
    glm::dvec3 sum(0.0);
    for (uint32_t t : tris) sum += tris_[t].normal * tris_[t].area;
    glm::dvec3 axis = glm::length(sum) > 0 ? glm::normalize(sum) : tris_[tris[0]].normal;
    glm::dvec3 u, v;
    planeBasis(axis, u, v);
    corners.resize(tris.size() * 3);
    bool facing = true;
    for (size_t i = 0; i < tris.size(); ++i) {
        facing = facing && glm::dot(tris_[tris[i]].normal, axis) >= cosPlanar_;
        for (uint32_t c = 0; c < 3; ++c) {
            glm::dvec3 p = position(tris[i], c);
            corners[3 * i + c] = glm::dvec2(glm::dot(p, u), glm::dot(p, v));
        }
    }
    distortion = measureDistortion(surfaceCorners(tris), corners);
    return tris.size() == 1 || (facing && !pieceSelfOverlaps(corners));
}

// Minimum-area rectangle of a subset of the piece whose corners were just flattened.
double Charter::subsetRectArea(const std::vector<uint32_t>& subset,
                               const std::vector<glm::dvec2>& corners) {
    std::vector<glm::dvec2> points;
    points.reserve(subset.size() * 3);
    for (uint32_t t : subset)
        for (uint32_t c = 0; c < 3; ++c) points.push_back(corners[3 * slotOf_[t] + c]);
    return minAreaRect(points).area;
}

// Flattens connected pieces conformally, else by projection, else cuts them in two across their
// longest extent and retries the halves. A single triangle always flattens.
void Charter::flattenPieces(std::vector<std::vector<uint32_t>> work,
                            std::vector<Flattened>& charts) {
    std::vector<glm::dvec2> corners;
    while (!work.empty()) {
        std::vector<uint32_t> tris = std::move(work.back());
        work.pop_back();
        ChartDistortion distortion;
        ChartKind kind = ChartKind::Conformal;
        bool flat = tris.size() > 1 && flattenConformal(tris, corners, distortion);
        if (!flat) kind = ChartKind::Planar, flat = flattenPlanar(tris, corners, distortion);
        std::vector<uint32_t> lower, upper;
        if (!flat || tris.size() >= kMinTrianglesToSplitForFill) splitInHalves(tris, lower, upper);
        if (!flat) {
            for (auto* part : {&lower, &upper})
                for (auto& piece : connectedPieces(*part)) work.push_back(std::move(piece));
            continue;
        }
        if (!lower.empty() && !upper.empty()) {
            // Packing follows each chart's outline one column at a time, so a ring or a long
            // curved strip still wastes its inside. Cut it in two when the halves' rectangles are
            // clearly smaller.
            double area = 0;
            for (size_t i = 0; i < tris.size(); ++i) {
                glm::dvec2 e1 = corners[3 * i + 1] - corners[3 * i],
                           e2 = corners[3 * i + 2] - corners[3 * i];
                area += 0.5 * std::abs(e1.x * e2.y - e1.y * e2.x);
                slotOf_[tris[i]] = uint32_t(i);
            }
            double rect = minAreaRect(corners).area;
            // Both halves must stay connected: pieces of one chart may only meet along shared
            // edges, else the gap between them would be narrower than a gutter.
            if (area < kMinRectFill * rect &&
                subsetRectArea(lower, corners) + subsetRectArea(upper, corners) <
                    kMinSplitGain * rect &&
                connectedPieces(lower).size() == 1 && connectedPieces(upper).size() == 1) {
                work.push_back(std::move(lower));
                work.push_back(std::move(upper));
                continue;
            }
        }
        charts.push_back({std::move(tris), corners, kind, distortion});
    }
}

// Charts a connected piece grown with the wide cone (wide) or the narrow one. A wide piece that
// does not flatten whole is cut in halves, and also grown again with the narrow cone within its
// triangles; the way that makes fewer charts (less gutter), then less rectangle area, is kept.
void Charter::chartPiece(std::vector<uint32_t> piece, bool wide) {
    std::vector<Flattened> charts;
    std::vector<uint32_t> copy = wide ? piece : std::vector<uint32_t>();
    flattenPieces({std::move(piece)}, charts);
    if (wide && charts.size() > 1) {
        std::vector<std::vector<uint32_t>> regrown;
        for (const std::vector<uint32_t>& grown : growCharts(std::move(copy), narrowGrowth_))
            for (std::vector<uint32_t>& p : connectedPieces(grown)) regrown.push_back(std::move(p));
        std::vector<Flattened> narrow;
        flattenPieces(std::move(regrown), narrow);
        auto rectArea = [](const std::vector<Flattened>& set) {
            double sum = 0;
            for (const Flattened& f : set) sum += minAreaRect(f.corners).area;
            return sum;
        };
        if (narrow.size() < charts.size() ||
            (narrow.size() == charts.size() && rectArea(narrow) < rectArea(charts)))
            charts = std::move(narrow);
    }
    for (const Flattened& f : charts) emitChart(f.tris, f.corners, f.kind, f.distortion);
}

void Charter::splitInHalves(const std::vector<uint32_t>& tris, std::vector<uint32_t>& lower,
                            std::vector<uint32_t>& upper) const {
    glm::dvec3 lo(1e300), hi(-1e300);
    std::vector<std::pair<double, uint32_t>> keyed(tris.size());
    for (size_t i = 0; i < tris.size(); ++i) {
        glm::dvec3 c = position(tris[i], 0) + position(tris[i], 1) + position(tris[i], 2);
        lo = glm::min(lo, c), hi = glm::max(hi, c);
    }
    glm::dvec3 ext = hi - lo;
    int axisIndex = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
    for (size_t i = 0; i < tris.size(); ++i) {
        uint32_t t = tris[i];
        keyed[i] = {(position(t, 0) + position(t, 1) + position(t, 2))[axisIndex], t};
    }
    std::sort(keyed.begin(), keyed.end());
    lower.clear(), upper.clear();
    for (size_t i = 0; i < keyed.size(); ++i)
        (i < keyed.size() / 2 ? lower : upper).push_back(keyed[i].second);
}

void Charter::emitChart(const std::vector<uint32_t>& tris, const std::vector<glm::dvec2>& corners,
                        ChartKind kind, const ChartDistortion& distortion) {
    uint32_t chartIndex = uint32_t(out_.charts.size());
    Chart chart;
    chart.kind = kind;
    chart.meanStretch = distortion.meanStretch();
    chart.maxStretch = distortion.maxStretch();
    if (distortion.maxSigma > 0) {
        double m2 = distortion.maxSigma * distortion.maxSigma;
        chart.densitySum = distortion.areaScale / m2;
        chart.densitySquareSum = distortion.areaScaleSquared / (m2 * m2);
    }
    chart.firstVertex = uint32_t(out_.vertexRemap.size());
    for (size_t i = 0; i < tris.size(); ++i) {
        uint32_t t = tris[i];
        chart.surfaceArea += tris_[t].area;
        for (uint32_t c = 0; c < 3; ++c) {
            uint32_t src = mesh_.indices[3 * t + c];
            if (vertexStamp_[src] != chartIndex + 1) {
                vertexStamp_[src] = chartIndex + 1;
                vertexBaked_[src] = uint32_t(out_.vertexRemap.size());
                out_.vertexRemap.push_back(src);
                out_.local.push_back(corners[3 * i + c]);
            }
            out_.indices[3 * t + c] = vertexBaked_[src];
        }
    }
    chart.vertexCount = uint32_t(out_.vertexRemap.size()) - chart.firstVertex;
    std::vector<glm::dvec2> coords(out_.local.begin() + chart.firstVertex, out_.local.end());
    chart.extent = alignToMinAreaRect(coords);
    std::copy(coords.begin(), coords.end(), out_.local.begin() + chart.firstVertex);
    out_.charts.push_back(chart);
}

// Zero-area triangles never produce a pixel, so nothing will ever sample them, but every
// triangle must own an ID texel. Each gets its own unit cell holding a small proper triangle
// over the cell centre (its own three baked vertices); the cells are packed edge to edge as one
// chart, with no gutters between them since no filter ever reads them.
void Charter::emitDegenerateCells() {
    std::vector<uint32_t> degenerate;
    for (uint32_t t = 0; t < tris_.size(); ++t)
        if (tris_[t].degenerate) degenerate.push_back(t);
    out_.degenerateTriangles = uint32_t(degenerate.size());
    if (degenerate.empty()) return;
    uint32_t side = uint32_t(std::ceil(std::sqrt(double(degenerate.size()))));
    uint32_t rows = (uint32_t(degenerate.size()) + side - 1) / side;
    Chart chart;
    chart.kind = ChartKind::DegenerateCells;
    chart.firstVertex = uint32_t(out_.vertexRemap.size());
    static const glm::dvec2 kCellCorners[3] = {{0.15, 0.15}, {0.95, 0.15}, {0.15, 0.95}};
    for (uint32_t i = 0; i < degenerate.size(); ++i) {
        uint32_t t = degenerate[i];
        glm::dvec2 cell(i % side, i / side);
        for (uint32_t c = 0; c < 3; ++c) {
            out_.indices[3 * t + c] = uint32_t(out_.vertexRemap.size());
            out_.vertexRemap.push_back(mesh_.indices[3 * t + c]);
            out_.local.push_back(cell + kCellCorners[c]);
        }
    }
    chart.vertexCount = uint32_t(out_.vertexRemap.size()) - chart.firstVertex;
    chart.extent = glm::dvec2(side, rows);
    out_.charts.push_back(chart);
}

ChartedMesh Charter::run() {
    if (mesh_.indices.size() % 3 != 0)
        throw InputError(format("mesh '%s': index count %zu is not a multiple of 3",
                                mesh_.name.c_str(), mesh_.indices.size()));
    for (uint32_t i : mesh_.indices)
        if (i >= mesh_.vertices.size())
            throw InputError(format("mesh '%s': index %u out of range (%zu vertices)",
                                    mesh_.name.c_str(), i, mesh_.vertices.size()));
    weld_ = weldPositions(mesh_, weldPosition_);
    classifyTriangles();
    neighbour_ = buildNeighbours(mesh_.indices, weld_, tris_);
    stamp_.assign(tris_.size(), 0);
    slotOf_.assign(tris_.size(), 0);
    localOf_.assign(weldPosition_.size(), kNone);
    vertexStamp_.assign(mesh_.vertices.size(), 0);
    vertexBaked_.assign(mesh_.vertices.size(), 0);
    out_.indices.assign(mesh_.indices.size(), 0);

    chartOf_.assign(tris_.size(), kOutside);
    std::vector<uint32_t> all;
    for (uint32_t t = 0; t < tris_.size(); ++t)
        if (!tris_[t].degenerate) all.push_back(t);
    for (const std::vector<uint32_t>& grown : growCharts(std::move(all), wideGrowth_))
        for (std::vector<uint32_t>& piece : connectedPieces(grown))
            chartPiece(std::move(piece), wideGrowth_ > narrowGrowth_);
    emitDegenerateCells();
    return std::move(out_);
}

// Area-weighted coefficient of variation of the density over the non-degenerate charts, each
// normalized by its maxSigma as packing will (the measure bake_validate.h bounds).
double meshDensityCv(const ChartedMesh& charted) {
    double area = 0, sum = 0, sumSquares = 0;
    for (const Chart& chart : charted.charts) {
        if (chart.kind == ChartKind::DegenerateCells) continue;
        area += chart.surfaceArea;
        sum += chart.densitySum, sumSquares += chart.densitySquareSum;
    }
    if (!(area > 0) || !(sum > 0)) return 0;
    double mean = sum / area;
    return std::sqrt(std::max(0.0, sumSquares / area - mean * mean)) / mean;
}

} // namespace

ChartedMesh buildCharts(const Mesh& mesh, const ChartingSettings& settings) {
    ChartedMesh loose = Charter(mesh, settings, kLooseChartDensityDeviation).run();
    if (meshDensityCv(loose) <= kMaxMeshDensityCv) return loose;
    return Charter(mesh, settings, kSafeChartDensityDeviation).run();
}

} // namespace shadel
