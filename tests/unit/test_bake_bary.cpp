// The C++ side of shaders/common/shadel_bary.h (the GLSL side is the same text).
#include <gtest/gtest.h>

#include "common/shadel_bary.h"

using namespace shadel::shader;

TEST(ShadelBary, InsidePointReproducesItself) {
    vec2 a(0.1f, 0.2f), b(0.8f, 0.25f), c(0.3f, 0.9f);
    vec2 p = a * 0.2f + b * 0.3f + c * 0.5f;
    vec3 w = shadelBarycentrics(p, a, b, c);
    EXPECT_NEAR(w.x, 0.2f, 1e-5f);
    EXPECT_NEAR(w.y, 0.3f, 1e-5f);
    EXPECT_NEAR(w.z, 0.5f, 1e-5f);
    vec2 q = shadelInterpolate2(w, a, b, c);
    EXPECT_NEAR(q.x, p.x, 1e-6f);
    EXPECT_NEAR(q.y, p.y, 1e-6f);
}

TEST(ShadelBary, ExtrapolatesLinearlyWithinEpsilonAndClampsBeyond) {
    vec2 a(0, 0), b(1, 0), c(0, 1);
    // Slightly outside: unclamped, the plane continues (this is what avoids edge artefacts).
    vec3 w = shadelBarycentrics(vec2(-0.3f, 0.4f), a, b, c);
    EXPECT_NEAR(w.y, -0.3f, 1e-6f);
    EXPECT_NEAR(w.z, 0.4f, 1e-6f);
    EXPECT_NEAR(w.x, 0.9f, 1e-6f);
    // Far outside: the free coordinates stop at -eps / 1 + eps, and the weights still sum to 1.
    w = shadelBarycentrics(vec2(-5.0f, 7.0f), a, b, c);
    EXPECT_FLOAT_EQ(w.y, -kShadelBaryEpsilon);
    EXPECT_FLOAT_EQ(w.z, 1.0f + kShadelBaryEpsilon);
    EXPECT_NEAR(w.x + w.y + w.z, 1.0f, 1e-6f);
}

TEST(ShadelBary, DegenerateTriangleGivesCentroidNotNaN) {
    vec3 w = shadelBarycentrics(vec2(0.5f), vec2(0.2f), vec2(0.2f), vec2(0.7f));
    EXPECT_FLOAT_EQ(w.x, 1.0f / 3.0f);
    EXPECT_FLOAT_EQ(w.y, 1.0f / 3.0f);
    EXPECT_FLOAT_EQ(w.z, 1.0f / 3.0f);
}

TEST(ShadelBary, ShadelCentreConventionAndNeighbours) {
    uvec2 size = shadelLevelSize(uvec2(64, 32), 1); // MIP 1 of a 64x32 rect
    EXPECT_EQ(size, uvec2(32, 16));
    vec2 centre = shadelCenterUv(uvec2(3, 5), size);
    EXPECT_FLOAT_EQ(centre.x, 3.5f / 32.0f);
    EXPECT_FLOAT_EQ(centre.y, 5.5f / 16.0f);
    // With the triangle spanning the whole rect as uv = (x, y), barycentrics are positions.
    vec2 a(0, 0), b(1, 0), c(0, 1);
    ShadelBary r = shadelBaryWithNeighbours(uvec2(3, 5), size, a, b, c);
    EXPECT_NEAR(r.center.y, 3.5f / 32, 1e-6f);
    EXPECT_NEAR(r.center.z, 5.5f / 16, 1e-6f);
    EXPECT_NEAR(r.right.y - r.center.y, 1.0f / 32, 1e-6f);
    EXPECT_NEAR(r.right.z - r.center.z, 0.0f, 1e-6f);
    EXPECT_NEAR(r.down.z - r.center.z, 1.0f / 16, 1e-6f);
    EXPECT_NEAR(r.down.y - r.center.y, 0.0f, 1e-6f);
    // Derivatives of a position attribute: one shadel step in world units.
    vec3 p0(0, 0, 0), p1(2, 0, 0), p2(0, 0, 4);
    vec3 ddx = shadelInterpolate(r.right, p0, p1, p2) - shadelInterpolate(r.center, p0, p1, p2);
    EXPECT_NEAR(ddx.x, 2.0f / 32, 1e-5f);
}
