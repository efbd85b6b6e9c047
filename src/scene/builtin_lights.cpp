#include "scene/builtin_lights.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "scene/mesh_utils.h"

namespace shadel {

namespace {

// splitmix64, as builtin_scenes.cpp: identical scenes on every platform.
struct Rng {
    uint64_t state;
    uint64_t next() {
        uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    float uniform(float lo, float hi) {
        return lo + (hi - lo) * float(next() >> 40) / float(1ull << 24);
    }
    int range(int lo, int hi) { return lo + int(next() % uint64_t(hi - lo + 1)); }
};

uint32_t addMaterial(Scene& scene, const std::string& name, glm::vec3 color, float roughness) {
    Material m;
    m.name = name;
    m.baseColorFactor = glm::vec4(color, 1.0f);
    m.roughnessFactor = roughness;
    scene.materials.push_back(m);
    return uint32_t(scene.materials.size() - 1);
}

// A box of `size` whose base centre is `base`.
void addBox(Scene& scene, const std::string& name, glm::vec3 size, glm::vec3 base,
            uint32_t material) {
    scene.meshes.push_back(makeBox(name, size, material));
    Instance inst;
    inst.name = name;
    inst.mesh = uint32_t(scene.meshes.size() - 1);
    inst.transform = glm::translate(glm::mat4(1.0f), base + glm::vec3(0, size.y * 0.5f, 0));
    scene.instances.push_back(inst);
}

uint32_t addBlocker(Scene& scene, const std::string& name, glm::vec3 center, glm::vec3 axisU,
                    glm::vec2 halfSize) {
    LightBlocker b;
    b.name = name;
    b.center = center;
    b.axisU = axisU;
    b.axisV = glm::vec3(0, 1, 0);
    b.halfSize = halfSize;
    scene.blockers.push_back(b);
    return uint32_t(scene.blockers.size() - 1);
}

Light light(LightType type, const std::string& name, glm::vec3 position, glm::vec3 color,
            float intensity, float range) {
    Light l;
    l.type = type;
    l.name = name;
    l.position = position;
    l.color = color;
    l.intensity = intensity;
    l.range = range;
    return l;
}

glm::vec3 warmOrCool(Rng& rng) {
    const glm::vec3 palette[6] = {{1.0f, 0.78f, 0.5f}, {1.0f, 0.9f, 0.75f}, {0.6f, 0.75f, 1.0f},
                                  {1.0f, 0.4f, 0.6f},  {0.5f, 1.0f, 0.7f},  {1.0f, 0.6f, 0.3f}};
    return palette[rng.range(0, 5)];
}

} // namespace

std::vector<uint32_t> addRoom(Scene& scene, const std::string& name, glm::vec3 center,
                              glm::vec2 size, float height, float doorWidth, float doorHeight,
                              uint32_t wallMaterial) {
    const float t = 0.2f; // wall thickness; blockers lie on the walls' mid-planes
    float hx = size.x * 0.5f + t * 0.5f, hz = size.y * 0.5f + t * 0.5f;
    float outerX = size.x + 2.0f * t;
    std::vector<uint32_t> blockers;
    glm::vec2 wallHalf(hx + t * 0.5f, height * 0.5f);
    // Back (-z) wall, side walls.
    addBox(scene, name + " back wall", {outerX, height, t}, center + glm::vec3(0, 0, -hz),
           wallMaterial);
    blockers.push_back(addBlocker(scene, name + " back", center + glm::vec3(0, height * 0.5f, -hz),
                                  {1, 0, 0}, wallHalf));
    for (float side : {-1.0f, 1.0f}) {
        addBox(scene, name + (side < 0 ? " west wall" : " east wall"), {t, height, size.y},
               center + glm::vec3(side * hx, 0, 0), wallMaterial);
        blockers.push_back(addBlocker(scene, name + (side < 0 ? " west" : " east"),
                                      center + glm::vec3(side * hx, height * 0.5f, 0), {0, 0, 1},
                                      glm::vec2(hz + t * 0.5f, height * 0.5f)));
    }
    // Front (+z) wall, with a doorway in the middle.
    glm::vec3 front = center + glm::vec3(0, 0, hz);
    if (doorWidth > 0.0f) {
        float segment = (outerX - doorWidth) * 0.5f;
        for (float side : {-1.0f, 1.0f})
            addBox(scene, name + " front wall", {segment, height, t},
                   front + glm::vec3(side * (doorWidth + segment) * 0.5f, 0, 0), wallMaterial);
        addBox(scene, name + " lintel", {doorWidth, height - doorHeight, t},
               front + glm::vec3(0, doorHeight, 0), wallMaterial);
    } else {
        addBox(scene, name + " front wall", {outerX, height, t}, front, wallMaterial);
    }
    uint32_t frontBlocker = addBlocker(scene, name + " front",
                                       front + glm::vec3(0, height * 0.5f, 0), {1, 0, 0}, wallHalf);
    if (doorWidth > 0.0f)
        scene.blockers[frontBlocker].portals.push_back(
            {{-doorWidth * 0.5f, -height * 0.5f}, {doorWidth * 0.5f, doorHeight - height * 0.5f}});
    blockers.push_back(frontBlocker);
    return blockers;
}

Scene makeBlockersScene() {
    Scene scene;
    scene.name = "blockers";
    scene.skyColor = glm::vec3(0.01f, 0.012f, 0.02f);
    scene.ambientColor = glm::vec3(0.0f); // only the lamp lights anything: leaks are plain
    uint32_t ground = addMaterial(scene, "ground", {0.6f, 0.6f, 0.6f}, 0.85f);
    uint32_t wall = addMaterial(scene, "wall", {0.75f, 0.7f, 0.62f}, 0.8f);
    scene.meshes.push_back(makePlane("ground", 30.0f, 30.0f, ground, 6));
    scene.instances.push_back({"ground", uint32_t(scene.meshes.size() - 1), glm::mat4(1.0f)});
    std::vector<uint32_t> walls =
        addRoom(scene, "room", {0, 0, 0}, {4.0f, 4.0f}, 2.5f, 1.0f, 2.0f, wall);
    Light lamp = light(LightType::Point, "room lamp", {0.0f, 1.5f, 0.0f}, {1.0f, 0.85f, 0.65f},
                       30.0f, 14.0f);
    lamp.blockers = walls;
    scene.lights.push_back(lamp);
    // Every built-in scene has one shadowed directional light; this one is dark, so that
    // everything outside the room shows only what leaks from the lamp.
    Light moon;
    moon.name = "moon (dark)";
    moon.type = LightType::Directional;
    moon.direction = glm::normalize(glm::vec3(-0.3f, -1.0f, -0.2f));
    moon.intensity = 0.0f;
    moon.castsShadow = true;
    scene.lights.push_back(moon);
    Camera top; // looking straight down: pixels map to the ground plane (the leak test)
    top.name = "main";
    top.position = {0.0f, 22.0f, 0.0f};
    top.forward = {0, -1, 0};
    top.up = {0, 0, -1};
    top.yfov = 0.7f;
    top.znear = 1.0f;
    top.zfar = 60.0f;
    scene.cameras.push_back(top);
    Camera side;
    side.name = "side";
    side.position = {5.0f, 5.0f, 9.0f};
    side.forward = glm::normalize(glm::vec3(0, 0.5f, 0) - side.position);
    side.up = glm::normalize(glm::vec3(0, 1, 0) - side.forward * side.forward.y);
    side.znear = 0.1f;
    side.zfar = 80.0f;
    scene.cameras.push_back(side);
    return scene;
}

Scene makeLightsScene(Scene scene) {
    scene.name = "lights";
    Rng rng{0x11647500001ull};
    // Night: a dim moon instead of the sun, dark sky and ambient.
    for (Light& l : scene.lights)
        if (l.type == LightType::Directional) {
            l.intensity = 0.12f;
            l.color = {0.6f, 0.7f, 1.0f};
        }
    scene.skyColor = glm::vec3(0.012f, 0.018f, 0.04f);
    scene.ambientColor = glm::vec3(0.012f, 0.014f, 0.02f);

    // Streets: the lines between the 15 m lots (buildings reach at most 7 m from a lot centre),
    // and the open avenue and plaza. A position on a street, at a height.
    auto onStreet = [&](float lo, float hi) {
        float along = rng.uniform(-55.0f, 55.0f);
        float across = 7.5f + 15.0f * float(rng.range(-4, 3)) + rng.uniform(-0.3f, 0.3f);
        if (rng.range(0, 3) == 0) across = rng.uniform(-6.5f, 6.5f); // the avenue (z) / plaza
        glm::vec3 p = rng.range(0, 1) ? glm::vec3(along, 0, across) : glm::vec3(across, 0, along);
        p.y = rng.uniform(lo, hi);
        return p;
    };
    auto name = [](const char* kind, int i) { return std::string(kind) + " " + std::to_string(i); };
    for (int i = 0; i < 800; ++i)
        scene.lights.push_back(light(LightType::Point, name("omni", i), onStreet(2.5f, 5.0f),
                                     warmOrCool(rng), rng.uniform(3.0f, 10.0f),
                                     rng.uniform(4.0f, 7.0f)));
    for (int i = 0; i < 300; ++i) {
        Light l = light(LightType::Spot, name("spot", i), onStreet(4.0f, 6.0f), warmOrCool(rng),
                        rng.uniform(15.0f, 40.0f), rng.uniform(7.0f, 10.0f));
        l.direction =
            glm::normalize(glm::vec3(rng.uniform(-0.3f, 0.3f), -1.0f, rng.uniform(-0.3f, 0.3f)));
        l.innerConeAngle = rng.uniform(0.2f, 0.4f);
        l.outerConeAngle = l.innerConeAngle + rng.uniform(0.1f, 0.3f);
        scene.lights.push_back(l);
    }
    for (int i = 0; i < 300; ++i) {
        Light l = light(LightType::SquareSpot, name("square spot", i), onStreet(3.0f, 6.0f),
                        warmOrCool(rng), rng.uniform(15.0f, 40.0f), rng.uniform(7.0f, 10.0f));
        float yaw = rng.uniform(0.0f, 6.2831853f);
        l.direction =
            glm::normalize(glm::vec3(std::cos(yaw), -rng.uniform(0.5f, 2.0f), std::sin(yaw)));
        l.axis = glm::vec3(-std::sin(yaw), 0.0f, std::cos(yaw));
        l.innerConeAngle = rng.uniform(0.2f, 0.35f);
        l.outerConeAngle = l.innerConeAngle + rng.uniform(0.05f, 0.2f);
        scene.lights.push_back(l);
    }
    for (int i = 0; i < 300; ++i) {
        Light l = light(LightType::Tube, name("tube", i), onStreet(2.5f, 4.0f), warmOrCool(rng),
                        rng.uniform(4.0f, 12.0f), rng.uniform(4.0f, 6.0f));
        l.axis = rng.range(0, 1) ? glm::vec3(1, 0, 0) : glm::vec3(0, 0, 1);
        l.tubeLength = rng.uniform(1.0f, 3.0f);
        l.tubeRadius = 0.04f;
        scene.lights.push_back(l);
    }
    for (int i = 0; i < 150; ++i) { // darks: pools of shade under awnings
        Light l = light(LightType::Point, name("dark", i), onStreet(1.0f, 2.5f), glm::vec3(1.0f),
                        rng.uniform(1.0f, 3.0f), rng.uniform(3.0f, 5.0f));
        l.dark = true;
        scene.lights.push_back(l);
    }
    for (int i = 0; i < 150; ++i) { // clip-planed: light only one side of a vertical plane
        Light l = light(LightType::Point, name("clipped", i), onStreet(2.0f, 4.0f), warmOrCool(rng),
                        rng.uniform(5.0f, 12.0f), rng.uniform(5.0f, 8.0f));
        glm::vec3 n = rng.range(0, 1) ? glm::vec3(1, 0, 0) : glm::vec3(0, 0, 1);
        if (rng.range(0, 1)) n = -n;
        l.hasClipPlane = true;
        l.clipPlane = glm::vec4(n, -glm::dot(n, l.position));
        scene.lights.push_back(l);
    }
    // Rooms along the avenue, doorways onto it; each has lamps its walls block.
    uint32_t wall = addMaterial(scene, "room wall", {0.7f, 0.66f, 0.6f}, 0.8f);
    const float roomX[4] = {-44.0f, -34.0f, 34.0f, 44.0f};
    for (int r = 0; r < 4; ++r) {
        glm::vec3 at{roomX[r], 0.0f, -5.0f};
        std::vector<uint32_t> walls =
            addRoom(scene, name("room", r), at, {5.0f, 3.0f}, 3.0f, 1.2f, 2.2f, wall);
        for (int k = 0; k < 3; ++k) {
            Light l = light(LightType::Point, name("room lamp", r * 3 + k),
                            at + glm::vec3(-1.5f + 1.5f * float(k), 2.2f, 0.0f),
                            {1.0f, 0.75f, 0.45f}, 25.0f, 10.0f);
            l.blockers = walls;
            scene.lights.push_back(l);
        }
    }
    // The first camera is the default: down the avenue at night, the rooms on the right.
    for (Camera& c : scene.cameras)
        if (c.name == "main") c.name = "plaza"; // the town's main camera; ours comes first
    Camera night;
    night.name = "main";
    night.position = {-54.0f, 2.2f, 4.0f};
    night.forward = glm::normalize(glm::vec3(0.0f, 1.0f, -3.0f) - night.position);
    night.up = glm::normalize(glm::vec3(0, 1, 0) - night.forward * night.forward.y);
    night.znear = 0.1f;
    night.zfar = 400.0f;
    scene.cameras.insert(scene.cameras.begin(), night);
    // Shadowed spots (render/lighting/spot_shadows.h: one atlas): 16 lamps down the avenue in
    // front of the night camera, each over a post it throws a shadow of onto the street; every
    // other one round or square, soft (PCSS, a 0.4 m lamp head) or hard (PCF).
    uint32_t postMaterial = addMaterial(scene, "shadow post", {0.5f, 0.5f, 0.55f}, 0.6f);
    for (int i = 0; i < 16; ++i) {
        float x = -47.0f + 2.0f * float(i);
        float z = (i % 2 == 0 ? -2.5f : 2.5f) + rng.uniform(-0.5f, 0.5f);
        addBox(scene, name("shadow post", i), {0.3f, 2.2f, 0.3f}, {x + 1.2f, 0.0f, z},
               postMaterial);
        Light l = light(i % 4 < 2 ? LightType::Spot : LightType::SquareSpot,
                        name("shadowed spot", i), {x, 5.0f, z}, warmOrCool(rng), 40.0f, 10.0f);
        l.direction = glm::normalize(glm::vec3(0.45f, -1.0f, 0.0f));
        l.axis = glm::vec3(0, 0, 1);
        l.innerConeAngle = 0.35f;
        l.outerConeAngle = 0.6f;
        l.castsShadow = true;
        l.softShadow = i % 2 == 0;
        l.lightSize = 0.4f;
        scene.lights.push_back(l);
    }
    return scene;
}

} // namespace shadel
