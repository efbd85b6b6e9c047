// Baking the built-in scenes and real glTF models (Debian's assimp test models): every mesh
// meets bakeViolation's bounds (bake_validate.h). Prints the figures `shadel bake` reports.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>

#include "bake/bake.h"
#include "bake/bake_validate.h"
#include "scene/load.h"

using namespace shadel;

namespace {

// Validation walks every shadel of every level, several times the cost of the bake, so the
// test bakes at a reduced density (the invariants do not depend on it); the opt-in
// DISABLED_DefaultDensityFigures prints the figures at the default settings.
void bakeAndValidateScene(const std::string& spec, float shadelsPerMetre) {
    Scene scene = loadScene(spec);
    BakeSettings settings;
    settings.shadelsPerMetre = shadelsPerMetre;
    auto start = std::chrono::steady_clock::now();
    std::vector<BakedMesh> baked = bakeScene(scene, settings, "");
    double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_EQ(baked.size(), scene.meshes.size());
    double worstCv = 0, worstError = 0;
    for (size_t i = 0; i < baked.size(); ++i) {
        BakeValidation v = validateBake(scene.meshes[i], baked[i]);
        BakeSettings meshSettings = settings;
        meshSettings.shadelsPerMetre = baked[i].shadelsPerMetre;
        EXPECT_EQ(bakeViolation(v, meshSettings), "")
            << spec << " mesh " << i << " '" << scene.meshes[i].name << "'";
        worstCv = std::max(worstCv, v.densityCv);
        worstError = std::max(worstError, v.maxReconstructionError);
    }
    std::printf(
        "[bake] %s @ %g/m: %zu meshes, %zu instances; worst density CV %.3f, worst reconstruction "
        "error %.5f shadels\n%s",
        spec.c_str(), double(shadelsPerMetre), scene.meshes.size(), scene.instances.size(), worstCv,
        worstError, bakeReport(baked, seconds).c_str());
}

const char* kModelDir = "/usr/share/assimp/models/glTF2";

} // namespace

TEST(BakeScenes, BuiltinScenes) {
    for (const std::string& name : builtinSceneNames())
        bakeAndValidateScene("builtin:" + name, 8.0f);
}

TEST(BakeScenes, RealGltfModels) {
    // The engine is modelled in millimetres without a unit scale (745 units wide): 0.032 per
    // unit is 32 per metre of the real engine.
    const std::pair<const char*, float> models[] = {
        {"2CylinderEngine-glTF-Binary/2CylinderEngine.glb", 0.032f},
        {"ClearCoat-glTF/ClearCoatTest.gltf", 32.0f},
        {"BoxTextured-glTF/BoxTextured.gltf", 32.0f},
        {"BoxBadNormals-glTF-Binary/BoxBadNormals.glb", 32.0f},
        {"glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf", 32.0f},
    };
    // scripts/setup.sh installs assimp-testmodels: a missing model fails (never a silent skip).
    for (auto [model, density] : models) {
        std::string path = std::string(kModelDir) + "/" + model;
        if (!std::filesystem::exists(path)) {
            ADD_FAILURE() << path << " is missing: install assimp-testmodels (scripts/setup.sh)";
            continue;
        }
        bakeAndValidateScene(path, density);
    }
}

// Opt-in (--gtest_also_run_disabled_tests): bake-only figures at the default settings, as
// `shadel bake` would print them.
TEST(BakeScenes, DISABLED_DefaultDensityFigures) {
    for (const char* spec :
         {"builtin:default",
          "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb",
          "/usr/share/assimp/models/glTF2/ClearCoat-glTF/ClearCoatTest.gltf"}) {
        if (spec[0] == '/' && !std::filesystem::exists(spec)) continue;
        Scene scene = loadScene(spec);
        auto start = std::chrono::steady_clock::now();
        std::vector<BakedMesh> baked = bakeScene(scene, BakeSettings{}, "");
        double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::printf("[bake] %s (default settings, 2 threads)\n%s", spec,
                    bakeReport(baked, seconds).c_str());
    }
}
