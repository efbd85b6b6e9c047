#include "bake/id_map.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "bake/bake.h"
#include "core/assert.h"

namespace shadel {
namespace {

constexpr int64_t kSub = 256; // fixed-point steps per shadel
constexpr int64_t kHalf = kSub / 2;

int64_t floorDiv(int64_t a, int64_t b) {
    return a >= 0 ? a / b : -((-a + b - 1) / b);
}
int64_t ceilDiv(int64_t a, int64_t b) {
    return -floorDiv(-a, b);
}

// One triangle in level shadel units: fixed point for coverage, double for distances.
struct LevelTriangle {
    int64_t x[3], y[3];
    int64_t area2 = 0; // > 0 after setup (counter-clockwise), 0 if degenerate
    glm::dvec2 p[3];

    int64_t edge(int i, int64_t px, int64_t py) const {
        int j = (i + 1) % 3;
        return (x[j] - x[i]) * (py - y[i]) - (y[j] - y[i]) * (px - x[i]);
    }
    // Top-left rule: an edge owns the points exactly on it iff its direction is in a half-open
    // half-plane of directions. A shared edge runs opposite ways in its two triangles, so
    // exactly one of them owns it.
    bool inclusive(int i) const {
        int j = (i + 1) % 3;
        int64_t dx = x[j] - x[i], dy = y[j] - y[i];
        return dy < 0 || (dy == 0 && dx > 0);
    }
    int64_t minX() const { return std::min({x[0], x[1], x[2]}); }
    int64_t maxX() const { return std::max({x[0], x[1], x[2]}); }
    int64_t minY() const { return std::min({y[0], y[1], y[2]}); }
    int64_t maxY() const { return std::max({y[0], y[1], y[2]}); }
};

LevelTriangle setupTriangle(const std::vector<glm::vec2>& uv, const std::vector<uint32_t>& indices,
                            uint32_t t, uint32_t width, uint32_t height) {
    LevelTriangle tri;
    for (int c = 0; c < 3; ++c) {
        glm::vec2 q = uv[indices[3 * t + c]];
        double fx = double(q.x) * width * kSub, fy = double(q.y) * height * kSub;
        // Clamp guards the arithmetic against non-finite input; shadel UVs are in [0,1].
        fx = std::isfinite(fx) ? std::clamp(fx, -1e9, 1e9) : 0.0;
        fy = std::isfinite(fy) ? std::clamp(fy, -1e9, 1e9) : 0.0;
        tri.x[c] = std::llround(fx);
        tri.y[c] = std::llround(fy);
    }
    tri.area2 = (tri.x[1] - tri.x[0]) * (tri.y[2] - tri.y[0]) -
                (tri.y[1] - tri.y[0]) * (tri.x[2] - tri.x[0]);
    if (tri.area2 < 0) {
        std::swap(tri.x[1], tri.x[2]);
        std::swap(tri.y[1], tri.y[2]);
        tri.area2 = -tri.area2;
    }
    for (int c = 0; c < 3; ++c) tri.p[c] = glm::dvec2(tri.x[c], tri.y[c]) / double(kSub);
    return tri;
}

// Chebyshev (L-infinity) distance from p to segment ab. max(|x(t)|, |y(t)|) is convex and
// piecewise linear in t with kinks only where |x| = |y|, so the minimum is at an end or a kink.
double segmentChebyshev(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
    glm::dvec2 d = b - a, r = a - p;
    auto at = [&](double t) {
        glm::dvec2 q = r + t * d;
        return std::max(std::abs(q.x), std::abs(q.y));
    };
    double best = std::min(at(0.0), at(1.0));
    if (d.x != d.y) {
        double t = (r.y - r.x) / (d.x - d.y);
        if (t > 0 && t < 1) best = std::min(best, at(t));
    }
    if (d.x != -d.y) {
        double t = -(r.x + r.y) / (d.x + d.y);
        if (t > 0 && t < 1) best = std::min(best, at(t));
    }
    return best;
}

// Chebyshev distance (shadels) from p to the closed triangle; 0 inside. Chebyshev, because the
// reconstruction filter's footprint is a square: a bilinear tap at a point of chart A reads
// shadels whose centres are < 1 shadel away from it in this metric. With charts 2g MIP-0 shadels
// apart, at MIP k <= log2(g) every such shadel is strictly nearer to A than to any other chart,
// so "nearest wins" hands all of them to A (see bake.h).
float distanceToTriangle(glm::dvec2 p, const LevelTriangle& tri) {
    if (tri.area2 > 0) {
        bool inside = true;
        for (int i = 0; i < 3 && inside; ++i) {
            glm::dvec2 a = tri.p[i], b = tri.p[(i + 1) % 3];
            inside = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x) >= 0;
        }
        if (inside) return 0.0f;
    }
    return float(
        std::min({segmentChebyshev(p, tri.p[0], tri.p[1]), segmentChebyshev(p, tri.p[1], tri.p[2]),
                  segmentChebyshev(p, tri.p[2], tri.p[0])}));
}

glm::dvec2 shadelCenter(int64_t x, int64_t y) {
    return glm::dvec2(double(x) + 0.5, double(y) + 0.5);
}

template <typename Visit>
void rasterizeStandard(const LevelTriangle& tri, uint32_t width, uint32_t height, Visit&& visit) {
    if (tri.area2 == 0) return;
    int64_t x0 = std::max<int64_t>(0, ceilDiv(tri.minX() - kHalf, kSub));
    int64_t x1 = std::min<int64_t>(int64_t(width) - 1, floorDiv(tri.maxX() - kHalf, kSub));
    int64_t y0 = std::max<int64_t>(0, ceilDiv(tri.minY() - kHalf, kSub));
    int64_t y1 = std::min<int64_t>(int64_t(height) - 1, floorDiv(tri.maxY() - kHalf, kSub));
    if (x0 > x1 || y0 > y1) return;
    int64_t stepX[3];
    bool inclusive[3];
    for (int i = 0; i < 3; ++i) {
        stepX[i] = -(tri.y[(i + 1) % 3] - tri.y[i]) * kSub;
        inclusive[i] = tri.inclusive(i);
    }
    for (int64_t y = y0; y <= y1; ++y) {
        int64_t py = y * kSub + kHalf;
        int64_t e[3];
        for (int i = 0; i < 3; ++i) e[i] = tri.edge(i, x0 * kSub + kHalf, py);
        for (int64_t x = x0; x <= x1; ++x) {
            bool in = true;
            for (int i = 0; i < 3; ++i) in = in && (e[i] > 0 || (e[i] == 0 && inclusive[i]));
            if (in) visit(uint32_t(x), uint32_t(y));
            for (int i = 0; i < 3; ++i) e[i] += stepX[i];
        }
    }
}

// Shadels whose square overlaps the triangle with positive area (exact separating-axis test:
// the two square axes via the bounding-box range, the three edges via the square's corner
// furthest inside each edge). A triangle with zero fixed-point area overlaps nothing with
// positive area, so it claims the shadels holding its corners instead.
template <typename Visit>
void rasterizeConservative(const LevelTriangle& tri, uint32_t width, uint32_t height,
                           Visit&& visit) {
    if (tri.area2 == 0) {
        for (int c = 0; c < 3; ++c) {
            int64_t x = std::clamp<int64_t>(floorDiv(tri.x[c], kSub), 0, int64_t(width) - 1);
            int64_t y = std::clamp<int64_t>(floorDiv(tri.y[c], kSub), 0, int64_t(height) - 1);
            visit(uint32_t(x), uint32_t(y));
        }
        return;
    }
    int64_t x0 = std::max<int64_t>(0, floorDiv(tri.minX(), kSub));
    int64_t x1 = std::min<int64_t>(int64_t(width) - 1, ceilDiv(tri.maxX(), kSub) - 1);
    int64_t y0 = std::max<int64_t>(0, floorDiv(tri.minY(), kSub));
    int64_t y1 = std::min<int64_t>(int64_t(height) - 1, ceilDiv(tri.maxY(), kSub) - 1);
    for (int64_t y = y0; y <= y1; ++y) {
        for (int64_t x = x0; x <= x1; ++x) {
            bool overlap = true;
            for (int i = 0; i < 3 && overlap; ++i) {
                int j = (i + 1) % 3;
                int64_t dx = tri.x[j] - tri.x[i], dy = tri.y[j] - tri.y[i];
                int64_t px = (-dy > 0) ? (x + 1) * kSub : x * kSub;
                int64_t py = (dx > 0) ? (y + 1) * kSub : y * kSub;
                overlap = tri.edge(i, px, py) > 0;
            }
            if (overlap) visit(uint32_t(x), uint32_t(y));
        }
    }
}

} // namespace

void forEachCoveredShadel(const std::vector<glm::vec2>& uv, const std::vector<uint32_t>& indices,
                          uint32_t width, uint32_t height,
                          const std::function<void(uint32_t, uint32_t, uint32_t)>& visit) {
    uint32_t triangles = uint32_t(indices.size() / 3);
    for (uint32_t t = 0; t < triangles; ++t) {
        LevelTriangle tri = setupTriangle(uv, indices, t, width, height);
        rasterizeStandard(tri, width, height, [&](uint32_t x, uint32_t y) { visit(t, x, y); });
    }
}

std::vector<uint16_t> buildIdMap(const std::vector<glm::vec2>& uv,
                                 const std::vector<uint32_t>& indices, uint32_t width,
                                 uint32_t height, const IdMapOptions& options, IdMapStats* stats) {
    IdMapStats local;
    IdMapStats& st = stats ? *stats : local;
    st = {};
    uint32_t triangles = uint32_t(indices.size() / 3);
    SHADEL_ASSERT(triangles <= kMaxTrianglesPerMesh);
    size_t texels = size_t(width) * height;
    std::vector<uint16_t> ids(texels, kEmptyShadel);
    if (texels == 0) return ids;

    std::vector<LevelTriangle> tris(triangles);
    for (uint32_t t = 0; t < triangles; ++t) tris[t] = setupTriangle(uv, indices, t, width, height);

    // Pass 1: standard coverage. Charts never overlap, so a shadel is claimed at most once; if
    // bad input overlaps anyway, the first triangle keeps it (deterministic).
    std::vector<uint32_t> owned(triangles, 0);
    for (uint32_t t = 0; t < triangles; ++t) {
        rasterizeStandard(tris[t], width, height, [&](uint32_t x, uint32_t y) {
            uint16_t& id = ids[size_t(y) * width + x];
            if (id == kEmptyShadel) id = uint16_t(t), ++owned[t], ++st.coveredShadels;
        });
    }

    // Pass 2: conservative coverage, only into shadels pass 1 left empty; nearest triangle wins.
    constexpr float kFar = std::numeric_limits<float>::infinity();
    std::vector<float> nearest(texels, kFar);
    std::vector<uint16_t> conservative(texels, kEmptyShadel);
    for (uint32_t t = 0; t < triangles; ++t) {
        rasterizeConservative(tris[t], width, height, [&](uint32_t x, uint32_t y) {
            size_t p = size_t(y) * width + x;
            if (ids[p] != kEmptyShadel) return;
            float d = distanceToTriangle(shadelCenter(x, y), tris[t]);
            if (d < nearest[p] || (d == nearest[p] && t < conservative[p]))
                nearest[p] = d, conservative[p] = uint16_t(t);
        });
    }
    for (size_t p = 0; p < texels; ++p) {
        if (ids[p] == kEmptyShadel && conservative[p] != kEmptyShadel) {
            ids[p] = conservative[p];
            ++owned[ids[p]];
            ++st.conservativeShadels;
        }
    }

    // Pass 3: a triangle that still owns nothing (tiny, or crowded out by neighbours) takes the
    // nearest shadel around it that is empty or whose owner keeps at least one other shadel.
    if (options.forceOwnership) {
        for (uint32_t t = 0; t < triangles; ++t) {
            if (owned[t] > 0) continue;
            const LevelTriangle& tri = tris[t];
            glm::dvec2 centroid = (tri.p[0] + tri.p[1] + tri.p[2]) / 3.0;
            int64_t cx = int64_t(std::floor(centroid.x)), cy = int64_t(std::floor(centroid.y));
            int64_t x0 = std::max({int64_t(0), floorDiv(tri.minX(), kSub) - 1, cx - 3});
            int64_t x1 = std::min({int64_t(width) - 1, floorDiv(tri.maxX(), kSub) + 1, cx + 3});
            int64_t y0 = std::max({int64_t(0), floorDiv(tri.minY(), kSub) - 1, cy - 3});
            int64_t y1 = std::min({int64_t(height) - 1, floorDiv(tri.maxY(), kSub) + 1, cy + 3});
            size_t best = texels;
            float bestScore = kFar;
            for (int64_t y = y0; y <= y1; ++y) {
                for (int64_t x = x0; x <= x1; ++x) {
                    size_t p = size_t(y) * width + size_t(x);
                    bool empty = ids[p] == kEmptyShadel;
                    if (!empty && owned[ids[p]] <= 1) continue;
                    // Prefer stealing a shadel the triangle touches over an empty one further off.
                    float score =
                        distanceToTriangle(shadelCenter(x, y), tri) + (empty ? 0.25f : 0.0f);
                    if (score < bestScore) bestScore = score, best = p;
                }
            }
            if (best == texels) {
                ++st.unownedTriangles;
                continue;
            }
            if (ids[best] != kEmptyShadel) --owned[ids[best]];
            ids[best] = uint16_t(t);
            owned[t] = 1;
            ++st.forcedTriangles;
        }
    }

    // Pass 4: flood. Each ring gives an empty shadel the ID of the nearest triangle among its
    // eight neighbours' triangles (true distance, so a shadel between two charts goes to the
    // closer one, not to whichever ring reached it first).
    std::vector<uint16_t> previous;
    for (uint32_t pass = 0; pass < options.floodPasses; ++pass) {
        previous = ids;
        uint64_t filled = 0;
        for (uint32_t y = 0; y < height; ++y) {
            for (uint32_t x = 0; x < width; ++x) {
                size_t p = size_t(y) * width + x;
                if (previous[p] != kEmptyShadel) continue;
                uint16_t bestId = kEmptyShadel;
                float bestDistance = kFar;
                for (int dy = -1; dy <= 1; ++dy) {
                    int64_t ny = int64_t(y) + dy;
                    if (ny < 0 || ny >= int64_t(height)) continue;
                    for (int dx = -1; dx <= 1; ++dx) {
                        int64_t nx = int64_t(x) + dx;
                        if (nx < 0 || nx >= int64_t(width)) continue;
                        uint16_t candidate = previous[size_t(ny) * width + size_t(nx)];
                        if (candidate == kEmptyShadel || candidate == bestId) continue;
                        float d = distanceToTriangle(shadelCenter(x, y), tris[candidate]);
                        if (d < bestDistance || (d == bestDistance && candidate < bestId))
                            bestDistance = d, bestId = candidate;
                    }
                }
                if (bestId != kEmptyShadel) ids[p] = bestId, ++filled;
            }
        }
        st.floodedShadels += filled;
        if (filled == 0) break;
    }
    return ids;
}

} // namespace shadel
