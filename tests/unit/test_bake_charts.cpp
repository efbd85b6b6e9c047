// Conformal flattening (lscm.h), its distortion measure (stretch.h) and outline packing
// (chart_packing.h), each against a closed-form expectation or a brute-force check.
#include <gtest/gtest.h>

#include <cmath>

#include "bake/arap.h"
#include "bake/chart_packing.h"
#include "bake/lscm.h"
#include "bake/packing.h"
#include "bake/stretch.h"

using namespace shadel;

namespace {

constexpr double kPi = 3.14159265358979;

// n x m quads on a cylinder of radius r, spanning `angle` radians: developable, so a conformal
// flattening is an isometry up to scale.
void cylinderPatch(double r, double angle, uint32_t n, uint32_t m, std::vector<glm::dvec3>& p,
                   std::vector<uint32_t>& tris) {
    for (uint32_t j = 0; j <= m; ++j)
        for (uint32_t i = 0; i <= n; ++i) {
            double a = angle * i / n;
            p.emplace_back(r * std::cos(a), 0.7 * j / m, r * std::sin(a));
        }
    for (uint32_t j = 0; j < m; ++j)
        for (uint32_t i = 0; i < n; ++i) {
            uint32_t a = j * (n + 1) + i;
            tris.insert(tris.end(), {a, a + n + 1, a + 1, a + 1, a + n + 1, a + n + 2});
        }
}

ChartDistortion distortionOf(const std::vector<glm::dvec3>& p, const std::vector<uint32_t>& tris,
                             const std::vector<glm::dvec2>& uv, bool mirror) {
    std::vector<glm::dvec3> surface;
    std::vector<glm::dvec2> chart;
    for (uint32_t i : tris) {
        surface.push_back(p[i]);
        chart.push_back(mirror ? glm::dvec2(-uv[i].x, uv[i].y) : uv[i]);
    }
    return measureDistortion(surface, chart);
}

} // namespace

TEST(BakeStretch, PlanarProjectionOfTiltedTriangle) {
    // Tilted by 60 degrees about x, projected on z = 0: y shrinks by cos 60.
    double c = std::cos(kPi / 3), s = std::sin(kPi / 3);
    std::vector<glm::dvec3> surface = {{0, 0, 0}, {1, 0, 0}, {0, c, s}};
    std::vector<glm::dvec2> chart = {{0, 0}, {1, 0}, {0, c}};
    ChartDistortion d = measureDistortion(surface, chart);
    EXPECT_NEAR(d.maxSigma, 1.0, 1e-12);
    EXPECT_NEAR(d.minSigma, c, 1e-12);
    EXPECT_NEAR(d.maxStretch(), 2.0, 1e-12);
    EXPECT_EQ(d.flippedTriangles, 0u);
    std::swap(chart[1], chart[2]); // reversed winding
    EXPECT_EQ(measureDistortion(surface, chart).flippedTriangles, 1u);
}

TEST(BakeLscm, DevelopableCylinderPatchUnrollsWithoutStretch) {
    std::vector<glm::dvec3> p;
    std::vector<uint32_t> tris;
    cylinderPatch(0.5, 2.5, 24, 6, p, tris); // 143 degrees: planar projection would stretch 3x
    std::vector<glm::dvec2> uv;
    ASSERT_TRUE(lscmFlatten(p, tris, uv));
    ChartDistortion d = distortionOf(p, tris, uv, false);
    if (d.flippedTriangles) d = distortionOf(p, tris, uv, true);
    EXPECT_EQ(d.flippedTriangles, 0u);
    EXPECT_LT(d.maxStretch(), 1.01);
    // The pins (opposite corners) sit at their 3-D chord distance, the unrolled patch puts them
    // at the geodesic distance: the whole map is scaled by chord / geodesic.
    double chord = std::hypot(2 * 0.5 * std::sin(2.5 / 2), 0.7);
    double geodesic = std::hypot(0.5 * 2.5, 0.7);
    EXPECT_NEAR(d.maxSigma, chord / geodesic, 0.01);
}

TEST(BakeLscm, CurvedCapStretchesAndIsMeasured) {
    // A spherical cap of half-angle 70 degrees is not developable: the map stays fold-free but
    // its scale varies, which is what the charting's stretch bound catches.
    std::vector<glm::dvec3> p{{0, 0, 1}};
    std::vector<uint32_t> tris;
    const uint32_t rings = 8, sectors = 24;
    for (uint32_t r = 1; r <= rings; ++r)
        for (uint32_t s = 0; s < sectors; ++s) {
            double polar = 70.0 / 180 * kPi * r / rings, az = 2 * kPi * s / sectors;
            p.emplace_back(std::sin(polar) * std::cos(az), std::sin(polar) * std::sin(az),
                           std::cos(polar));
        }
    auto at = [&](uint32_t r, uint32_t s) {
        return r == 0 ? 0u : 1 + (r - 1) * sectors + s % sectors;
    };
    for (uint32_t r = 0; r < rings; ++r)
        for (uint32_t s = 0; s < sectors; ++s) {
            if (r == 0) {
                tris.insert(tris.end(), {0, at(1, s), at(1, s + 1)});
                continue;
            }
            tris.insert(tris.end(), {at(r, s), at(r + 1, s), at(r + 1, s + 1)});
            tris.insert(tris.end(), {at(r, s), at(r + 1, s + 1), at(r, s + 1)});
        }
    std::vector<glm::dvec2> uv;
    ASSERT_TRUE(lscmFlatten(p, tris, uv));
    ChartDistortion d = distortionOf(p, tris, uv, false);
    if (d.flippedTriangles) d = distortionOf(p, tris, uv, true);
    EXPECT_EQ(d.flippedTriangles, 0u);
    EXPECT_GT(d.maxStretch(), 1.2);
    EXPECT_LT(d.maxStretch(), 2.0);
    EXPECT_GE(d.meanStretch(), 1.0);
    EXPECT_LE(d.meanStretch(), d.maxStretch());

    // ARAP from there spreads the distortion: the density (relative to the chart's densest
    // point) gets more uniform, and nothing folds.
    bool mirrored = distortionOf(p, tris, uv, false).flippedTriangles > 0;
    if (mirrored)
        for (glm::dvec2& q : uv) q.x = -q.x;
    ASSERT_TRUE(arapRefine(p, tris, uv, 8));
    ChartDistortion rigid = distortionOf(p, tris, uv, false);
    std::printf(
        "[bake] 70-degree cap: LSCM density deviation %.3f stretch %.3f, ARAP %.3f / %.3f\n",
        d.densityDeviation(), d.maxStretch(), rigid.densityDeviation(), rigid.maxStretch());
    EXPECT_EQ(rigid.flippedTriangles, 0u);
    EXPECT_LT(rigid.densityDeviation(), 0.8 * d.densityDeviation());
}

TEST(BakeOutlinePacking, OutlinesNeverOverlapAndBeatRectsOnLShapes) {
    // L-shaped charts (two triangles per arm), various sizes; gutter 2.
    const uint32_t gutter = 2;
    std::vector<std::array<ChartOutline, kOrientations>> outlines;
    std::vector<PackRect> rects;
    uint32_t seed = 777;
    for (int c = 0; c < 120; ++c) {
        seed = seed * 1664525u + 1013904223u;
        double w = 6 + (seed >> 8) % 30, h = 6 + (seed >> 16) % 30, t = 3;
        // Arms along the bottom and the left side of a w x h box.
        std::vector<glm::dvec2> corners = {{0, 0}, {w, 0}, {w, t}, {0, 0}, {w, t}, {0, t},
                                           {0, t}, {t, t}, {t, h}, {0, t}, {t, h}, {0, h}};
        glm::uvec2 content{uint32_t(w), uint32_t(h)};
        for (uint32_t k = 0; k < 4; ++k) {
            std::vector<glm::dvec2> turned;
            for (glm::dvec2 q : corners) turned.push_back(turnQuarter(q, glm::dvec2(content), k));
            glm::uvec2 box = k % 2 ? glm::uvec2(content.y, content.x) : content;
            if (k == 0) outlines.emplace_back();
            outlines.back()[k] = chartOutline(turned, box, gutter);
        }
        rects.push_back({content.x + 2 * gutter, content.y + 2 * gutter});
    }
    OutlinePack pack = packOutlines(outlines, gutter, 8);
    ASSERT_EQ(pack.placements.size(), outlines.size());
    EXPECT_EQ(pack.width % 8, 0u);
    EXPECT_EQ(pack.height % 8, 0u);
    // Outlines may overhang the rect by the gutter: check them on the rect grown by it, and the
    // content (outline shrunk by the gutter) inside the rect.
    uint32_t gridWidth = pack.width + 2 * gutter, gridHeight = pack.height + 2 * gutter;
    std::vector<uint8_t> grid(size_t(gridWidth) * gridHeight, 0);
    for (size_t c = 0; c < outlines.size(); ++c) {
        const OutlinePlacement& at = pack.placements[c];
        const ChartOutline& o = outlines[c][at.orientation];
        for (uint32_t i = 0; i < o.width; ++i)
            for (uint32_t k = o.first[i]; k < o.first[i + 1]; ++k)
                for (uint32_t y = o.runs[k].x; y < o.runs[k].y; ++y) {
                    ASSERT_LT(at.x + i, gridWidth);
                    ASSERT_LT(at.y + y, gridHeight);
                    ASSERT_EQ(grid[size_t(at.y + y) * gridWidth + at.x + i]++, 0) << "chart " << c;
                }
        // The content box (outline minus the gutter ring) lies inside the rect.
        EXPECT_LE(at.x + o.width - 2 * gutter, pack.width);
        EXPECT_LE(at.y + o.height - 2 * gutter, pack.height);
    }
    PackResult boxes = packNearSquare(rects, 8);
    double outlineArea = double(pack.width) * pack.height,
           rectArea = double(boxes.width) * boxes.height;
    std::printf("[bake] L shapes: outlines %ux%u, rects %ux%u (%.0f%%)\n", pack.width, pack.height,
                boxes.width, boxes.height, 100 * outlineArea / rectArea);
    EXPECT_LT(outlineArea, 0.85 * rectArea);
}

TEST(BakeOutlinePacking, OutlineCoversEveryTouchedShadelPlusGutter) {
    // One triangle; every shadel it overlaps must lie inside the outline shrunk by the gutter.
    std::vector<glm::dvec2> tri = {{0.5, 0.2}, {9.7, 3.1}, {2.2, 6.9}};
    ChartOutline o = chartOutline(tri, {10, 7}, 2);
    EXPECT_EQ(o.width, 14u);
    EXPECT_EQ(o.height, 11u);
    for (int x = 0; x < 10; ++x)
        for (int y = 0; y < 7; ++y) {
            // Shadel (x, y) overlaps the triangle if its centre is inside, a conservative subset.
            glm::dvec2 c(x + 0.5, y + 0.5);
            auto side = [&](glm::dvec2 a, glm::dvec2 b) {
                return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
            };
            if (side(tri[0], tri[1]) < 0 || side(tri[1], tri[2]) < 0 || side(tri[2], tri[0]) < 0)
                continue;
            for (int dx = -2; dx <= 2; ++dx) {
                // Outline column x + 2 + dx must hold rows y .. y + 4 (content row y + 2, +-2).
                uint32_t column = uint32_t(x + 2 + dx);
                bool covered = false;
                for (uint32_t k = o.first[column]; k < o.first[column + 1]; ++k)
                    covered =
                        covered || (o.runs[k].x <= uint32_t(y) && o.runs[k].y >= uint32_t(y + 5));
                EXPECT_TRUE(covered) << x << "," << y << " column " << column;
            }
        }
}

TEST(BakeOutlinePacking, SmallChartFallsIntoARingsHole) {
    // A ring 40 shadels wide with a 24-shadel hole, and a 6 x 6 square: packed together they
    // need no more room than the ring alone.
    std::vector<glm::dvec2> ring;
    const int segments = 32;
    for (int s = 0; s < segments; ++s) {
        double a0 = 2 * 3.14159265358979 * s / segments,
               a1 = 2 * 3.14159265358979 * (s + 1) / segments;
        glm::dvec2 c(20, 20);
        glm::dvec2 i0 = c + 12.0 * glm::dvec2(std::cos(a0), std::sin(a0)),
                   i1 = c + 12.0 * glm::dvec2(std::cos(a1), std::sin(a1));
        glm::dvec2 o0 = c + 19.9 * glm::dvec2(std::cos(a0), std::sin(a0)),
                   o1 = c + 19.9 * glm::dvec2(std::cos(a1), std::sin(a1));
        ring.insert(ring.end(), {i0, o0, o1, i0, o1, i1});
    }
    std::vector<glm::dvec2> square = {{0, 0}, {6, 0}, {6, 6}, {0, 0}, {6, 6}, {0, 6}};
    std::vector<std::array<ChartOutline, kOrientations>> outlines(2);
    for (uint32_t k = 0; k < 4; ++k) {
        outlines[0][k] = chartOutline(ring, {40, 40}, 2);
        outlines[1][k] = chartOutline(square, {6, 6}, 2);
    }
    OutlinePack alone = packOutlines({outlines[0]}, 2, 8);
    OutlinePack both = packOutlines(outlines, 2, 8);
    EXPECT_EQ(uint64_t(both.width) * both.height, uint64_t(alone.width) * alone.height);
    const OutlinePlacement& p = both.placements[1];
    EXPECT_GT(p.x, both.placements[0].x + 8);
    EXPECT_GT(p.y, both.placements[0].y + 8);
}
