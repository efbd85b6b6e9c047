// Shadel baking on procedural meshes built to be awkward: curved closed surfaces, seams,
// degenerate / flipped / non-manifold triangles, a projection that overlaps itself, and a
// 65k-triangle mesh. Every bake is checked with validateBake + bakeViolation (bounds stated in
// bake_validate.h).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "bake/bake.h"
#include "bake/bake_validate.h"
#include "bake/id_map.h"
#include "bake/packing.h"
#include "core/error.h"
#include "scene/mesh_utils.h"

using namespace shadel;

namespace {

constexpr float kPi = 3.14159265358979f;

void addVertex(Mesh& m, glm::vec3 p) {
    Vertex v{};
    v.position = p;
    v.normal = glm::vec3(0, 1, 0);
    v.tangent = glm::vec4(1, 0, 0, 1);
    m.vertices.push_back(v);
}

void addTriangle(Mesh& m, uint32_t a, uint32_t b, uint32_t c) {
    m.indices.insert(m.indices.end(), {a, b, c});
}

// Closed torus in the XZ plane, nu x nv quads.
Mesh makeTorus(float major, float minor, uint32_t nu, uint32_t nv) {
    Mesh m;
    m.name = "torus";
    for (uint32_t i = 0; i < nu; ++i) {
        for (uint32_t j = 0; j < nv; ++j) {
            float u = 2 * kPi * i / nu, v = 2 * kPi * j / nv;
            float r = major + minor * std::cos(v);
            addVertex(m, {r * std::cos(u), minor * std::sin(v), r * std::sin(u)});
        }
    }
    for (uint32_t i = 0; i < nu; ++i) {
        for (uint32_t j = 0; j < nv; ++j) {
            uint32_t a = i * nv + j, b = ((i + 1) % nu) * nv + j;
            uint32_t c = ((i + 1) % nu) * nv + (j + 1) % nv, d = i * nv + (j + 1) % nv;
            addTriangle(m, a, c, b);
            addTriangle(m, a, d, c);
        }
    }
    return m;
}

// A height field over [0,size]^2, n x n quads.
Mesh makeTerrain(uint32_t n, float size, float amplitude) {
    Mesh m;
    m.name = "terrain";
    for (uint32_t y = 0; y <= n; ++y)
        for (uint32_t x = 0; x <= n; ++x) {
            float fx = size * x / n, fz = size * y / n;
            addVertex(m, {fx, amplitude * std::sin(fx * 1.3f) * std::cos(fz * 0.9f), fz});
        }
    for (uint32_t y = 0; y < n; ++y)
        for (uint32_t x = 0; x < n; ++x) {
            uint32_t a = y * (n + 1) + x;
            addTriangle(m, a, a + n + 1, a + 1);
            addTriangle(m, a + 1, a + n + 1, a + n + 2);
        }
    return m;
}

// A ramp spiralling twice around the Y axis with a shallow pitch: its normals all lie in a narrow
// cone around +Y, so it grows as one chart, but projected on the XZ plane it overlaps itself.
Mesh makeSpiralRamp() {
    Mesh m;
    m.name = "spiral";
    const uint32_t steps = 96;
    for (uint32_t i = 0; i <= steps; ++i) {
        float a = 4 * kPi * i / steps, h = 0.05f * i;
        addVertex(m, {1.0f * std::cos(a), h, 1.0f * std::sin(a)});
        addVertex(m, {2.0f * std::cos(a), h, 2.0f * std::sin(a)});
    }
    for (uint32_t i = 0; i < steps; ++i) {
        uint32_t a = 2 * i;
        addTriangle(m, a, a + 2, a + 1);
        addTriangle(m, a + 1, a + 2, a + 3);
    }
    return m;
}

// Everything the importers let through and worse: zero-area triangles (repeated index,
// collinear, a NaN corner), flipped triangles, a duplicated triangle, a non-manifold fin,
// a disconnected speck and an open fan.
Mesh makeNastyMesh() {
    Mesh m = makeTerrain(12, 3.0f, 0.2f);
    m.name = "nasty";
    for (size_t t = 0; t < m.indices.size() / 3; t += 7)
        std::swap(m.indices[3 * t + 1], m.indices[3 * t + 2]);
    uint32_t base = uint32_t(m.vertices.size());
    addVertex(m, {0, 2, 0}), addVertex(m, {1, 2, 0}), addVertex(m, {2, 2, 0}); // collinear
    addTriangle(m, base, base + 1, base + 2);
    addTriangle(m, base, base, base + 1); // repeated index
    addVertex(m, {std::numeric_limits<float>::quiet_NaN(), 0, 0});
    addTriangle(m, base, base + 1, base + 3); // NaN corner
    addTriangle(m, 0, 1, 14); // duplicate of terrain's first triangle (winding flipped)
    addTriangle(m, 0, 14, 1); // and once more as is: a three-way edge
    addVertex(m, {0.1f, 1.0f, 0.1f});
    addTriangle(m, 0, 1, base + 4); // fin on an existing edge: non-manifold
    addVertex(m, {5, 5, 5}), addVertex(m, {5.0001f, 5, 5}), addVertex(m, {5, 5.0001f, 5});
    addTriangle(m, base + 5, base + 6, base + 7); // disconnected sub-shadel speck
    uint32_t centre = uint32_t(m.vertices.size());
    addVertex(m, {-3, 0, -3});
    for (int i = 0; i <= 40; ++i) {
        float a = 1.5f * kPi * i / 40;
        addVertex(m, {-3 + std::cos(a), 0.3f * std::sin(3 * a), -3 + std::sin(a)});
        if (i > 0) addTriangle(m, centre, centre + i + 1, centre + i);
    }
    return m;
}

BakedMesh bakeAndCheck(const Mesh& mesh, const BakeSettings& settings = {}) {
    BakedMesh baked = bakeMesh(mesh, settings);
    BakeValidation v = validateBake(mesh, baked);
    EXPECT_EQ(bakeViolation(v, settings), "") << mesh.name;
    std::printf("[bake] %-10s tris %6u charts %5u  %4ux%-4u mips %u  util %.1f%%  density %.1f/m "
                "(cv %.3f)  forced %u degenerate %u  spacing %.3f..%.3f  err %.5f  %.3f s\n",
                mesh.name.c_str(), baked.triangleCount, baked.chartCount, baked.width, baked.height,
                baked.mipCount(), 100.0 * baked.utilisation, baked.shadelsPerMetre, v.densityCv,
                baked.forcedTriangles, baked.degenerateTriangles, v.minNeighbourSpacing,
                v.maxNeighbourSpacing, v.maxReconstructionError, baked.bakeSeconds);
    return baked;
}

} // namespace

TEST(BakeMipCount, StopsAtOneChunk) {
    EXPECT_EQ(bakedMipCount(8, 8), 1u);
    EXPECT_EQ(bakedMipCount(16, 8), 1u);
    EXPECT_EQ(bakedMipCount(16, 16), 2u);
    EXPECT_EQ(bakedMipCount(24, 40), 2u);
    EXPECT_EQ(bakedMipCount(4096, 4096), 10u);
}

TEST(BakeIdMap, QuadPartitionsEveryShadelExactlyOnce) {
    // Two triangles covering the whole rect, sharing a diagonal through shadel centres.
    std::vector<glm::vec2> uv = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    std::vector<uint32_t> indices = {0, 1, 2, 0, 2, 3};
    std::vector<uint32_t> hits(32 * 32, 0);
    forEachCoveredShadel(uv, indices, 32, 32,
                         [&](uint32_t, uint32_t x, uint32_t y) { ++hits[y * 32 + x]; });
    for (uint32_t h : hits) ASSERT_EQ(h, 1u);
}

TEST(BakeIdMap, TinyTriangleGetsConservativeShadelAndFloodFillsAround) {
    // 0.2 shadels wide, between shadel centres: the standard pass misses it.
    glm::vec2 o(10.6f / 32, 10.6f / 32);
    std::vector<glm::vec2> uv = {o, o + glm::vec2(0.2f / 32, 0), o + glm::vec2(0, 0.2f / 32)};
    std::vector<uint32_t> indices = {0, 1, 2};
    IdMapOptions options;
    options.floodPasses = 2;
    IdMapStats stats;
    std::vector<uint16_t> ids = buildIdMap(uv, indices, 32, 32, options, &stats);
    EXPECT_EQ(stats.coveredShadels, 0u);
    EXPECT_EQ(stats.conservativeShadels, 1u);
    EXPECT_EQ(ids[10 * 32 + 10], 0);
    EXPECT_EQ(ids[12 * 32 + 12], 0);            // two flood rings
    EXPECT_EQ(ids[13 * 32 + 13], kEmptyShadel); // not three
}

TEST(BakeIdMap, ForceAssignsCrowdedTriangles) {
    // Nine triangles inside one shadel: one wins the conservative pass, the rest are forced
    // onto neighbouring shadels.
    std::vector<glm::vec2> uv;
    std::vector<uint32_t> indices;
    for (int i = 0; i < 9; ++i) {
        glm::vec2 o = glm::vec2(8.1f + 0.1f * i, 8.1f) / 16.0f;
        uint32_t b = uint32_t(uv.size());
        uv.insert(uv.end(), {o, o + glm::vec2(0.05f / 16, 0), o + glm::vec2(0, 0.05f / 16)});
        indices.insert(indices.end(), {b, b + 1, b + 2});
    }
    IdMapOptions options;
    options.forceOwnership = true;
    IdMapStats stats;
    std::vector<uint16_t> ids = buildIdMap(uv, indices, 16, 16, options, &stats);
    EXPECT_EQ(stats.forcedTriangles, 8u);
    EXPECT_EQ(stats.unownedTriangles, 0u);
    std::vector<int> owned(9, 0);
    for (uint16_t id : ids)
        if (id != kEmptyShadel) owned[id]++;
    for (int n : owned) EXPECT_GE(n, 1);
}

TEST(BakePacking, RectsDoNotOverlapAndFit) {
    std::vector<PackRect> rects;
    uint32_t seed = 12345;
    for (int i = 0; i < 300; ++i) {
        seed = seed * 1664525u + 1013904223u;
        rects.push_back({5 + (seed >> 8) % 60, 5 + (seed >> 20) % 30});
    }
    PackResult r = packNearSquare(rects, 8);
    ASSERT_EQ(r.placements.size(), rects.size());
    EXPECT_EQ(r.width % 8, 0u);
    EXPECT_EQ(r.height % 8, 0u);
    std::vector<uint8_t> grid(size_t(r.width) * r.height, 0);
    double area = 0;
    for (size_t i = 0; i < rects.size(); ++i) {
        uint32_t w = r.placements[i].turned ? rects[i].height : rects[i].width;
        uint32_t h = r.placements[i].turned ? rects[i].width : rects[i].height;
        ASSERT_LE(r.placements[i].x + w, r.width);
        ASSERT_LE(r.placements[i].y + h, r.height);
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x)
                ASSERT_EQ(grid[(r.placements[i].y + y) * r.width + r.placements[i].x + x]++, 0);
        area += double(w) * h;
    }
    double fill = area / (double(r.width) * r.height);
    std::printf("[bake] packer fill %.1f%% in %ux%u\n", 100 * fill, r.width, r.height);
    EXPECT_GT(fill, 0.75);
    EXPECT_LE(std::max(r.width, r.height), 2 * std::min(r.width, r.height));
}

TEST(BakeMesh, BoxWithSplitVertices) {
    bakeAndCheck(makeBox("box", {1, 2, 0.5f}, 0));
}

TEST(BakeMesh, SphereWithPoles) {
    BakedMesh b = bakeAndCheck(makeSphere("sphere", 1.0f, 0, 48, 24));
    EXPECT_GT(b.utilisation, 0.4f);
}

TEST(BakeMesh, TorusClosedSurface) {
    bakeAndCheck(makeTorus(1.0f, 0.35f, 48, 24));
}

TEST(BakeMesh, TerrainIsOneOrFewCharts) {
    BakedMesh b = bakeAndCheck(makeTerrain(32, 8.0f, 0.3f));
    EXPECT_LE(b.chartCount, 4u);
    EXPECT_GT(b.utilisation, 0.6f);
    // Density follows the setting (a 64 m^2 height field, not tiny, not huge).
    EXPECT_NEAR(b.shadelsPerMetre, 32.0f, 1e-3f);
}

TEST(BakeMesh, SelfOverlappingProjectionIsSplit) {
    Mesh spiral = makeSpiralRamp();
    BakedMesh b = bakeAndCheck(spiral);
    EXPECT_GE(b.chartCount, 2u); // one chart would overlap itself
}

TEST(BakeMesh, DegenerateFlippedNonManifoldAndDisconnected) {
    Mesh nasty = makeNastyMesh();
    BakedMesh b = bakeAndCheck(nasty);
    EXPECT_EQ(b.degenerateTriangles, 3u);
    EXPECT_EQ(b.unownedTriangles, 0u);
}

TEST(BakeMesh, TinyObjectFillsMinimumRect) {
    BakeSettings settings;
    settings.minResolution = 64;
    BakedMesh b = bakeAndCheck(makeBox("pebble", glm::vec3(0.05f), 0), settings);
    EXPECT_EQ(b.width, 64u);
    EXPECT_GT(b.shadelsPerMetre, 32.0f); // density raised to use the minimum rect
}

TEST(BakeMesh, HugeObjectIsClampedToMaxResolution) {
    BakeSettings settings;
    settings.maxResolution = 256;
    BakedMesh b = bakeAndCheck(makeTerrain(16, 100.0f, 2.0f), settings);
    EXPECT_LE(std::max(b.width, b.height), 256u);
    EXPECT_LT(b.shadelsPerMetre, 32.0f);
}

TEST(BakeMesh, EmptyMesh) {
    Mesh empty;
    BakedMesh b = bakeMesh(empty, {});
    EXPECT_EQ(b.width, 8u);
    EXPECT_EQ(b.mipCount(), 1u);
    EXPECT_TRUE(validateBake(empty, b).structureError.empty());
}

TEST(BakeMesh, RejectsBadInput) {
    Mesh bad = makeBox("bad", glm::vec3(1), 0);
    bad.indices[4] = 999;
    EXPECT_THROW(bakeMesh(bad, {}), InputError);
    BakeSettings settings;
    settings.shadelsPerMetre = 0;
    EXPECT_THROW(bakeMesh(makeBox("b", glm::vec3(1), 0), settings), InputError);
}

TEST(BakeMesh, Dense65kTriangles) {
    // 65 522 triangles on a 12 m^2 torus: ~5 shadels per triangle at the default density, so
    // the baker must raise the density until every triangle owns a shadel.
    Mesh torus = makeTorus(1.0f, 0.3f, 181, 181);
    ASSERT_LE(torus.triangleCount(), kMaxTrianglesPerMesh);
    auto start = std::chrono::steady_clock::now();
    BakedMesh b = bakeAndCheck(torus);
    double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("[bake] 65k-triangle torus: %.2f s (bake + validation)\n", seconds);
    EXPECT_EQ(b.unownedTriangles, 0u);
}

TEST(BakeMesh, Deterministic) {
    Mesh m = makeNastyMesh();
    BakedMesh a = bakeMesh(m, {}), b = bakeMesh(m, {});
    EXPECT_EQ(a.shadelUv, b.shadelUv);
    EXPECT_EQ(a.idMaps, b.idMaps);
}
