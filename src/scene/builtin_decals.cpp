#include "scene/builtin_decals.h"

#include <glm/gtc/matrix_transform.hpp>

#include "common/shared_types.h"
#include "scene/mesh_utils.h"

namespace shadel {

namespace {

constexpr glm::vec3 kFigure{1.9f, 0.0f, 0.9f};

uint32_t addMaterial(Scene& scene, const std::string& name, glm::vec3 color, float roughness) {
    Material m;
    m.name = name;
    m.baseColorFactor = glm::vec4(color, 1.0f);
    m.roughnessFactor = roughness;
    scene.materials.push_back(m);
    return uint32_t(scene.materials.size() - 1);
}

void addMesh(Scene& scene, Mesh mesh, glm::vec3 position) {
    scene.meshes.push_back(std::move(mesh));
    Instance inst;
    inst.name = scene.meshes.back().name;
    inst.mesh = uint32_t(scene.meshes.size() - 1);
    inst.transform = glm::translate(glm::mat4(1.0f), position);
    scene.instances.push_back(inst);
}

Decal decal(glm::vec3 center, glm::vec3 axisZ, glm::vec3 axisX, glm::vec3 size, uint32_t kinds,
            DecalPattern pattern) {
    Decal d;
    d.center = center;
    d.axisZ = axisZ;
    d.axisX = axisX;
    d.size = size;
    d.kinds = kinds;
    d.pattern = pattern;
    return d;
}

} // namespace

glm::vec3 decalsSceneContactShadowCentre() {
    return kFigure;
}

Scene makeDecalsScene() {
    Scene scene;
    scene.name = "decals";
    // A bright sky and ambient, so the AO-only decals have light to take away.
    scene.ambientColor = glm::vec3(0.3f, 0.32f, 0.36f);
    uint32_t ground = addMaterial(scene, "concrete", {0.55f, 0.54f, 0.5f}, 0.85f);
    uint32_t wall = addMaterial(scene, "wall", {0.72f, 0.7f, 0.64f}, 0.8f);
    uint32_t crate = addMaterial(scene, "crate", {0.5f, 0.38f, 0.24f}, 0.7f);
    uint32_t figure = addMaterial(scene, "figure", {0.3f, 0.45f, 0.6f}, 0.5f);
    addMesh(scene, makePlane("ground", 16.0f, 12.0f, ground, 4), {0.0f, 0.0f, 0.0f});
    addMesh(scene, makeBox("wall", {9.0f, 3.5f, 0.3f}, wall), {0.0f, 1.75f, -2.5f});
    addMesh(scene, makeBox("crate", {1.2f, 1.2f, 1.2f}, crate), {-1.8f, 0.6f, 0.2f});
    addMesh(scene, makeCylinder("figure", 0.3f, 1.7f, figure), kFigure);

    const glm::vec3 up{0, 1, 0}, front{0, 0, 1}, right{1, 0, 0};
    const uint32_t base = DECAL_KIND(DECAL_STAGE_BASE_COLOR);
    const uint32_t normal = DECAL_KIND(DECAL_STAGE_NORMAL);
    const uint32_t rough = DECAL_KIND(DECAL_STAGE_ROUGHNESS);
    const uint32_t ao = DECAL_KIND(DECAL_STAGE_AMBIENT_OCCLUSION);
    // Graffiti on the wall, two splats overlapping (the second drawn over the first).
    Decal red =
        decal({-0.6f, 1.9f, -2.35f}, front, right, {2.4f, 2.4f, 0.8f}, base, DecalPattern::Splat);
    red.color = {0.85f, 0.15f, 0.1f, 0.9f};
    scene.decals.push_back(red);
    Decal blue =
        decal({0.5f, 1.5f, -2.35f}, front, right, {2.0f, 2.0f, 0.8f}, base, DecalPattern::Splat);
    blue.color = {0.1f, 0.3f, 0.85f, 0.85f};
    scene.decals.push_back(blue);
    // A riveted plate over the graffiti's right edge: bumps (normal) and darker rivets.
    Decal plate = decal({1.6f, 1.6f, -2.35f}, front, right, {1.6f, 1.6f, 0.8f}, normal | base,
                        DecalPattern::Rivets);
    plate.color = {0.25f, 0.25f, 0.27f, 0.6f};
    plate.normalStrength = 4.0f;
    scene.decals.push_back(plate);
    // Rivets on the crate's front face (projected along +z, the ground beside it fades out).
    Decal crateRivets =
        decal({-1.8f, 0.6f, 0.8f}, front, right, {1.2f, 1.2f, 0.6f}, normal, DecalPattern::Rivets);
    crateRivets.normalStrength = 5.0f;
    scene.decals.push_back(crateRivets);
    // Road stripes on the ground, a puddle over them (roughness only).
    Decal stripes =
        decal({-0.1f, 0.0f, 1.6f}, up, right, {3.2f, 1.6f, 0.6f}, base, DecalPattern::Stripes);
    stripes.color = {0.95f, 0.8f, 0.1f, 0.9f};
    scene.decals.push_back(stripes);
    Decal puddle =
        decal({0.0f, 0.0f, 1.9f}, up, right, {2.2f, 1.6f, 0.6f}, rough, DecalPattern::Puddle);
    puddle.roughness = 0.08f;
    scene.decals.push_back(puddle);
    // Contact shadows: ambient occlusion only, under the figure and the crate.
    Decal figureShadow = decal(kFigure, up, right, {1.6f, 1.6f, 0.6f}, ao, DecalPattern::Blob);
    figureShadow.occlusion = 0.85f;
    scene.decals.push_back(figureShadow);
    Decal crateShadow =
        decal({-1.8f, 0.0f, 0.2f}, up, right, {2.4f, 2.4f, 0.6f}, ao, DecalPattern::Blob);
    crateShadow.occlusion = 0.6f;
    scene.decals.push_back(crateShadow);

    Light sun;
    sun.name = "sun";
    sun.type = LightType::Directional;
    sun.direction = glm::normalize(glm::vec3(-0.5f, -1.0f, -0.6f));
    sun.intensity = 1.6f;
    sun.color = {1.0f, 0.95f, 0.88f};
    sun.castsShadow = true;
    scene.lights.push_back(sun);
    Light lamp;
    lamp.name = "lamp";
    lamp.type = LightType::Point;
    lamp.position = {2.6f, 1.4f, 2.0f};
    lamp.color = {1.0f, 0.8f, 0.6f};
    lamp.intensity = 6.0f;
    lamp.range = 6.0f;
    scene.lights.push_back(lamp);

    Camera cam;
    cam.name = "main";
    cam.position = {0.4f, 3.0f, 7.0f};
    cam.forward = glm::normalize(glm::vec3(0.0f, 0.9f, -0.5f) - cam.position);
    cam.up = glm::normalize(up - cam.forward * glm::dot(up, cam.forward));
    cam.yfov = 0.8f;
    cam.znear = 0.1f;
    cam.zfar = 100.0f;
    scene.cameras.push_back(cam);
    return scene;
}

} // namespace shadel
