// One memory budget per scene load: small files that expand into much more memory (many images
// naming one PNG, many buffers naming one large sparse file, a big sparse accessor) stop at the
// limit with one line naming the input and what exceeded it; the same files load under a limit
// that holds them.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include <stb/stb_image_write.h>

#include "core/error.h"
#include "scene/load.h"
#include "scene/load_budget.h"
#include "temp_dir.h"

using namespace shadel;
using shadel::test::TempDir;
namespace fs = std::filesystem;

namespace {

// The process-wide limit for one test, restored after.
struct LimitForTest {
    explicit LimitForTest(uint64_t bytes) { setLoadMemoryLimit(bytes); }
    ~LimitForTest() { setLoadMemoryLimit(0); }
};

// One triangle whose material samples `imageCount` images, every one naming image.png.
std::string gltfSharingOneImage(const fs::path& dir, int imageCount) {
    const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::string images, textures;
    for (int i = 0; i < imageCount; ++i) {
        images += std::string(i ? "," : "") + R"({"uri":"image.png"})";
        textures += std::string(i ? "," : "") + R"({"source":)" + std::to_string(i) + "}";
    }
    std::ofstream(dir / "tri.bin", std::ios::binary)
        .write(reinterpret_cast<const char*>(p), sizeof p);
    return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
        "nodes":[{"mesh":0}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0}]}],
        "materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],
        "textures":[)" +
           textures + R"(],"images":[)" + images + R"(],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
                      "min":[0,0,0],"max":[1,1,0]}],
        "bufferViews":[{"buffer":0,"byteLength":36}],
        "buffers":[{"uri":"tri.bin","byteLength":36}]})";
}

std::string loadError(const std::string& path) {
    try {
        loadScene(path);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

} // namespace

TEST(LoadBudget, ManyImagesNamingOnePngStopAtTheLimit) {
    TempDir dir("shadel_load_budget");
    // A flat 1024x1024 PNG: a few kilobytes on disk, 4 MiB decoded.
    std::vector<uint8_t> pixels(1024 * 1024 * 4, 200);
    ASSERT_TRUE(
        stbi_write_png((dir.path / "image.png").c_str(), 1024, 1024, 4, pixels.data(), 1024 * 4));
    std::ofstream(dir.path / "many.gltf") << gltfSharingOneImage(dir.path, 20);
    std::ofstream(dir.path / "one.gltf") << gltfSharingOneImage(dir.path, 1);
    EXPECT_LT(fs::file_size(dir.path / "image.png"), 64u << 10);

    LimitForTest limit(64ull << 20); // 20 images x 4 MiB (and the scene's copy) is 160 MiB
    std::string error = loadError((dir.path / "many.gltf").string());
    EXPECT_NE(error.find("many.gltf: decoding an image needs 8.0 MiB more"), std::string::npos)
        << error;
    EXPECT_NE(error.find("over the 64 MiB load memory limit (--load-memory-limit)"),
              std::string::npos)
        << error;
    EXPECT_EQ(loadError((dir.path / "one.gltf").string()), "") << "one image fits";
}

TEST(LoadBudget, BuffersNamingOneLargeSparseFileStopAtTheLimit) {
    TempDir dir("shadel_load_budget");
    {
        std::ofstream big(dir.path / "big.bin", std::ios::binary);
        const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
        big.write(reinterpret_cast<const char*>(p), sizeof p);
    }
    fs::resize_file(dir.path / "big.bin", 48ull << 20); // sparse: no disk used
    std::string buffers, views;
    for (int i = 0; i < 8; ++i) {
        buffers += std::string(i ? "," : "") + R"({"uri":"big.bin","byteLength":)" +
                   std::to_string(48ull << 20) + "}";
    }
    std::ofstream(dir.path / "sparse.gltf") << R"({"asset":{"version":"2.0"},"scene":0,
        "scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
                      "min":[0,0,0],"max":[1,1,0]}],
        "bufferViews":[{"buffer":0,"byteLength":36}],"buffers":[)" +
                                                   buffers + "]}";
    LimitForTest limit(256ull << 20); // 8 x 48 MiB
    std::string error = loadError((dir.path / "sparse.gltf").string());
    EXPECT_NE(error.find("sparse.gltf: reading a buffer or image file needs 48.0 MiB more"),
              std::string::npos)
        << error;
}

TEST(LoadBudget, ABudgetIsPerLoadAndPerThread) {
    LimitForTest limit(1000);
    {
        LoadBudgetScope outer("outer.gltf");
        chargeLoadMemory(600, "first");
        EXPECT_EQ(outer.used(), 600u);
        {
            LoadBudgetScope inner("inner.gltf"); // its own 1000 bytes
            chargeLoadMemory(900, "inner");
            EXPECT_EQ(inner.used(), 900u);
        }
        try {
            chargeLoadMemory(401, "the straw");
            ADD_FAILURE() << "600 + 401 is over 1000";
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()).rfind("outer.gltf: the straw needs", 0), 0u)
                << e.what();
        }
        chargeLoadMemory(400, "exactly the rest");
        EXPECT_EQ(outer.used(), 1000u);
    }
    chargeLoadMemory(1ull << 40, "outside any load"); // no budget: nothing to charge
    EXPECT_LE(defaultLoadMemoryLimit(), 2ull << 30);
    EXPECT_GT(defaultLoadMemoryLimit(), 0u);
}
