#include "scene/builtin_materials.h"

#include <glm/gtc/matrix_transform.hpp>

#include "scene/mesh_utils.h"

namespace shadel {

namespace {

uint32_t addMaterial(Scene& scene, const std::string& name, glm::vec3 color, float roughness,
                     float metallic, const std::string& program) {
    Material m;
    m.name = name;
    m.baseColorFactor = glm::vec4(color, 1.0f);
    m.roughnessFactor = roughness;
    m.metallicFactor = metallic;
    m.shadelMaterial = program;
    scene.materials.push_back(m);
    return uint32_t(scene.materials.size() - 1);
}

void place(Scene& scene, Mesh mesh, glm::vec3 position) {
    Instance inst;
    inst.name = mesh.name;
    scene.meshes.push_back(std::move(mesh));
    inst.mesh = uint32_t(scene.meshes.size() - 1);
    inst.transform = glm::translate(glm::mat4(1.0f), position);
    scene.instances.push_back(std::move(inst));
}

void addCamera(Scene& scene, const std::string& name, glm::vec3 position, glm::vec3 target) {
    Camera c;
    c.name = name;
    c.position = position;
    c.forward = glm::normalize(target - position);
    glm::vec3 up = glm::vec3(0, 1, 0) - c.forward * glm::dot(glm::vec3(0, 1, 0), c.forward);
    c.up = glm::normalize(up);
    c.yfov = 0.8f;
    c.znear = 0.1f;
    c.zfar = 200.0f;
    scene.cameras.push_back(c);
}

} // namespace

Scene makeMaterialsScene() {
    Scene scene;
    scene.name = "materials";
    uint32_t terrain =
        addMaterial(scene, "terrain", {0.3f, 0.4f, 0.2f}, 0.85f, 0.0f, "builtin:terrain");
    uint32_t red = addMaterial(scene, "red (glTF PBR)", {0.75f, 0.15f, 0.12f}, 0.5f, 0.0f, "");
    Material bricks;
    bricks.name = "bricks (glTF PBR)";
    bricks.baseColorFactor = glm::vec4(0.62f, 0.28f, 0.2f, 1.0f);
    bricks.roughnessFactor = 0.85f;
    bricks.procedural = Procedural::Bricks;
    bricks.proceduralScale = 4.0f;
    scene.materials.push_back(bricks);
    uint32_t brick = uint32_t(scene.materials.size() - 1);
    uint32_t gold = addMaterial(scene, "gold (factors program)", {1.0f, 0.78f, 0.34f}, 0.35f, 1.0f,
                                "builtin:gltf_pbr_factors");
    uint32_t blue = addMaterial(scene, "blue (factors program)", {0.2f, 0.35f, 0.75f}, 0.6f, 0.0f,
                                "builtin:gltf_pbr_factors");
    // The accumulating program's wall: a one-texel checker of 1 cm cells (about half a pixel at
    // 192x108 from the checker camera), what the forward path's procedural of the same material
    // draws (the program's oracle).
    uint32_t checker = addMaterial(scene, "checker (accumulating program)", {0.85f, 0.85f, 0.82f},
                                   0.6f, 0.0f, "builtin:checker_accumulate");
    scene.materials[checker].procedural = Procedural::TexelChecker;
    scene.materials[checker].proceduralScale = 100.0f;

    place(scene, makePlane("terrain", 24.0f, 24.0f, terrain, 8), {0.0f, 0.0f, 0.0f});
    place(scene, makeSphere("red sphere", 0.8f, red, 48, 24), {-2.5f, 0.8f, 0.5f});
    place(scene, makeBox("brick box", {1.4f, 1.4f, 1.4f}, brick), {-0.6f, 0.7f, -1.5f});
    place(scene, makeSphere("gold sphere", 0.8f, gold, 48, 24), {1.2f, 0.8f, 0.8f});
    place(scene, makeBox("blue box", {1.2f, 1.6f, 1.2f}, blue), {3.0f, 0.8f, -1.0f});
    place(scene, makeBox("checker wall", {4.0f, 3.0f, 0.2f}, checker), {-6.0f, 1.5f, -4.0f});

    Light sun;
    sun.name = "sun";
    sun.type = LightType::Directional;
    sun.direction = glm::normalize(glm::vec3(-0.6f, -0.7f, -0.4f));
    sun.intensity = 3.0f;
    sun.color = {1.0f, 0.96f, 0.9f};
    sun.castsShadow = true;
    scene.lights.push_back(sun);
    Light lamp;
    lamp.name = "warm lamp";
    lamp.type = LightType::Point;
    lamp.position = {-1.0f, 2.5f, 3.0f};
    lamp.color = {1.0f, 0.75f, 0.5f};
    lamp.intensity = 20.0f;
    lamp.range = 12.0f;
    scene.lights.push_back(lamp);

    addCamera(scene, "main", {0.0f, 4.0f, 9.0f}, {0.0f, 0.5f, 0.0f});
    addCamera(scene, "terrain", {-6.0f, 2.5f, 6.0f}, {-2.0f, 0.0f, -3.0f});
    addCamera(scene, "factors", {2.1f, 1.1f, 3.6f}, {2.1f, 0.85f, -0.2f});
    addCamera(scene, "checker", {-6.0f, 1.5f, -1.4f}, {-6.0f, 1.5f, -4.0f});
    return scene;
}

} // namespace shadel
