// The particle lightmap atlas rules (shaders/particles/particle_atlas.h, shared with the GPU):
// LOD from the estimated screen size and the per-frame shelf packing.
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "particles/particle_atlas.h"

using namespace shadel::gpu;

TEST(ParticleAtlas, LodFollowsScreenSize) {
    // Near the camera: 32x32 by default, 128x128 at LOD 0 with the artist bias.
    EXPECT_EQ(particleAtlasSide(particleAtlasLod(0.5f, 0.0f)), 32u);
    EXPECT_EQ(particleAtlasSide(particleAtlasLod(PARTICLE_NEAR_SCREEN_FRACTION, 0.0f)), 32u);
    EXPECT_EQ(particleAtlasLod(0.5f, -5.0f), 0u);
    EXPECT_EQ(particleAtlasSide(0u), 128u);
    EXPECT_EQ(particleAtlasSide(particleAtlasLod(0.5f, -1.0f)), 40u);
    // One LOD lower per 25% less screen size.
    float near = PARTICLE_NEAR_SCREEN_FRACTION;
    EXPECT_EQ(particleAtlasLod(near * 0.76f, 0.0f), PARTICLE_ATLAS_DEFAULT_LOD);
    EXPECT_EQ(particleAtlasLod(near * 0.74f, 0.0f), PARTICLE_ATLAS_DEFAULT_LOD + 1u);
    EXPECT_EQ(particleAtlasLod(near * 0.75f * 0.74f, 0.0f), PARTICLE_ATLAS_DEFAULT_LOD + 2u);
    // Far sprites clamp to the smallest LOD; a huge bias clamps to LOD 0.
    EXPECT_EQ(particleAtlasLod(1e-4f, 0.0f), PARTICLE_ATLAS_LODS - 1u);
    EXPECT_EQ(particleAtlasLod(1e-4f, -100.0f), 0u);
    // Sides shrink monotonically, each about 3/4 of the one above.
    for (uint32_t l = 1; l < PARTICLE_ATLAS_LODS; ++l) {
        EXPECT_LT(particleAtlasSide(l), particleAtlasSide(l - 1));
        EXPECT_NEAR(float(particleAtlasSide(l)) / float(particleAtlasSide(l - 1)), 0.75f, 0.1f);
    }
}

// Random per-LOD counts: every rectangle that fits lies inside the atlas, none overlap, a few
// sprites per LOD always fit, and overflow only ever cuts the tail of the packing order.
TEST(ParticleAtlas, ShelfPackingNeverOverlaps) {
    std::mt19937 rng(7);
    for (int trial = 0; trial < 40; ++trial) {
        const uint32_t atlas = trial < 20 ? 1024 : 512;
        uint32_t counts[PARTICLE_ATLAS_LODS] = {};
        for (uint32_t l = 0; l < PARTICLE_ATLAS_LODS; ++l) {
            counts[l] = rng() % (trial < 20 ? 8 : 60);
        }
        bool overflowSeen = false;
        std::vector<uint8_t> owner(atlas * atlas, 0);
        uint64_t texels = 0, overflowed = 0;
        for (uint32_t l = 0; l < PARTICLE_ATLAS_LODS; ++l)
            for (uint32_t k = 0; k < counts[l]; ++k) {
                glm::uvec4 r = particleAtlasRect(counts, l, k, atlas);
                EXPECT_EQ(r.z, particleAtlasSide(l));
                if (r.w == 0u) {
                    ++overflowed;
                    overflowSeen = true;
                    continue;
                }
                EXPECT_FALSE(overflowSeen) << "a rectangle fits after one overflowed";
                ASSERT_LE(r.x + r.z, atlas);
                ASSERT_LE(r.y + r.z, atlas);
                for (uint32_t y = r.y; y < r.y + r.z; ++y)
                    for (uint32_t x = r.x; x < r.x + r.z; ++x) {
                        ASSERT_EQ(owner[y * atlas + x], 0) << "overlap at " << x << "," << y;
                        owner[y * atlas + x] = 1;
                    }
                texels += uint64_t(r.z) * r.z;
            }
        EXPECT_LE(texels, uint64_t(atlas) * atlas);
        if (trial < 20) {
            EXPECT_EQ(overflowed, 0u) << "up to 7 sprites per LOD fit in 1024^2";
        }
    }
}
