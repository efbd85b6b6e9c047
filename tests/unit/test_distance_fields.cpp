// Mesh distance fields (bake/mesh_distance_field.h) and their 3-D atlas
// (render/distance_fields/df_atlas.h).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "bake/mesh_distance_field.h"
#include "render/distance_fields/df_atlas.h"
#include "scene/mesh_utils.h"
#include "temp_dir.h"

using namespace shadel;

namespace {
bool overlaps(const Placement<3>& a, const Placement<3>& b) {
    for (int i = 0; i < 3; ++i)
        if (a.origin[i] + a.extent[i] <= b.origin[i] || b.origin[i] + b.extent[i] <= a.origin[i])
            return false;
    return true;
}
} // namespace

// Random adds and removes (objects streaming in and out): the live boxes never overlap, stay
// inside the atlas, keep their size, and freed room is reused.
TEST(DistanceFieldAtlas, NeverOverlapsAfterChurn) {
    DistanceFieldAtlas atlas({128, 128, 128});
    std::mt19937 rng(1234);
    std::uniform_int_distribution<uint32_t> side(4, 30), coin(0, 2);
    std::unordered_map<uint32_t, Extent<3>> asked;
    uint32_t nextKey = 0, placed = 0, refused = 0;
    for (int step = 0; step < 3000; ++step) {
        if (coin(rng) != 0 || atlas.boxes().empty()) {
            Extent<3> e{side(rng), side(rng), side(rng)};
            auto p = atlas.add(nextKey, e);
            if (p) {
                asked[nextKey] = e;
                ++placed;
            } else {
                ++refused;
            }
            ++nextKey;
        } else {
            auto it = atlas.boxes().begin();
            std::advance(it, rng() % atlas.boxes().size());
            uint32_t key = it->first;
            EXPECT_TRUE(atlas.remove(key));
            EXPECT_FALSE(atlas.remove(key));
            asked.erase(key);
        }
        if (step % 100 == 99) {
            ASSERT_TRUE(atlas.validate()) << step;
            std::vector<Placement<3>> live;
            for (const auto& [k, p] : atlas.boxes()) {
                for (int i = 0; i < 3; ++i) {
                    EXPECT_GE(p.extent[i], asked[k][i]);
                    EXPECT_LE(p.origin[i] + p.extent[i], 128u);
                }
                live.push_back(p);
            }
            for (size_t i = 0; i < live.size(); ++i)
                for (size_t j = i + 1; j < live.size(); ++j)
                    ASSERT_FALSE(overlaps(live[i], live[j])) << "step " << step;
        }
    }
    EXPECT_GT(placed, 1000u); // room freed by removals was reused
    EXPECT_GT(refused, 0u);   // and the atlas did fill up at times
}

// A box's field against the analytic box distance: inside negative, outside positive, close to
// exact (within half a voxel diagonal, trilinear not involved: voxel centres).
TEST(MeshDistanceField, BoxMatchesTheAnalyticDistance) {
    Mesh box = makeBox("box", {2.0f, 1.0f, 0.5f}, 0);
    MeshDistanceField f = buildMeshDistanceField(box, 20);
    ASSERT_GT(f.resolution.x, 4u);
    double worst = 0;
    int inside = 0;
    for (uint32_t z = 0; z < f.resolution.z; ++z)
        for (uint32_t y = 0; y < f.resolution.y; ++y)
            for (uint32_t x = 0; x < f.resolution.x; ++x) {
                glm::vec3 p = f.origin + glm::vec3(x, y, z) * f.voxelSize;
                glm::vec3 q = glm::abs(p) - glm::vec3(1.0f, 0.5f, 0.25f);
                float exact = glm::length(glm::max(q, 0.0f)) +
                              std::min(std::max(q.x, std::max(q.y, q.z)), 0.0f);
                worst = std::max(worst, double(std::abs(f.at(x, y, z) - exact)));
                inside += f.at(x, y, z) < 0;
            }
    EXPECT_LT(worst, 1e-3);
    EXPECT_GT(inside, 0);
}

TEST(MeshDistanceField, CachedFieldIsReadBackIdentical) {
    test::TempDir dir("sdf_cache");
    Mesh sphere = makeSphere("ball", 0.5f, 0, 12, 6);
    bool cached = true;
    MeshDistanceField a = loadOrBuildMeshDistanceField(sphere, dir.path.string(), &cached, 12);
    EXPECT_FALSE(cached);
    MeshDistanceField b = loadOrBuildMeshDistanceField(sphere, dir.path.string(), &cached, 12);
    EXPECT_TRUE(cached);
    EXPECT_EQ(a.resolution, b.resolution);
    EXPECT_EQ(a.distances, b.distances);
    // A corrupted file is rebuilt, not trusted.
    for (auto& e : std::filesystem::recursive_directory_iterator(dir.path))
        if (e.is_regular_file()) {
            std::FILE* fp = std::fopen(e.path().c_str(), "r+b");
            std::fseek(fp, -3, SEEK_END);
            std::fputc('X', fp);
            std::fclose(fp);
        }
    MeshDistanceField c = loadOrBuildMeshDistanceField(sphere, dir.path.string(), &cached, 12);
    EXPECT_FALSE(cached);
    EXPECT_EQ(a.distances, c.distances);
}
