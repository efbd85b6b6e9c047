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

float srgbEncode(float linear) {
    float c = std::clamp(linear, 0.0f, 1.0f);
    return c < 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

float smoothStep(float e0, float e1, float x) {
    float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

// 7-segment bits (a top, b upper right, c lower right, d bottom, e lower left, f upper left,
// g middle) of the sign's letters, "SHOP".
const uint8_t kSignLetters[4] = {0x6D, 0x76, 0x3F, 0x73};

// Linear colour of texel (x, y) of a light texture of w x h.
glm::vec3 lightTexel(LightTexture kind, uint32_t x, uint32_t y, uint32_t w, uint32_t h) {
    float u = (float(x) + 0.5f) / float(w), v = (float(y) + 0.5f) / float(h);
    float edge = 1.0f / float(w); // edges a texel soft, so MIPs and shadels filter them alike
    switch (kind) {
    case LightTexture::Window: {
        float frame = std::min(std::min(u, 1.0f - u), std::min(v, 1.0f - v));
        float pane = smoothStep(0.08f - edge, 0.08f + edge, frame) *
                     smoothStep(0.06f - edge, 0.06f + edge, std::abs(u - 0.5f)) *
                     smoothStep(0.06f - edge, 0.06f + edge, std::abs(v - 0.5f));
        return glm::vec3(1.0f, 0.92f, 0.78f) * pane;
    }
    case LightTexture::StainedGlass: {
        const glm::vec3 glass[6] = {{0.9f, 0.1f, 0.05f}, {1.0f, 0.55f, 0.05f},
                                    {0.1f, 0.25f, 1.0f}, {0.15f, 0.8f, 0.2f},
                                    {0.6f, 0.15f, 0.9f}, {0.95f, 0.95f, 0.85f}};
        auto lead = [](float t) { return std::abs(t * 3.0f - std::round(t * 3.0f)) / 3.0f; };
        float d = std::min(lead(u), lead(v));
        int cell = std::min(int(u * 3.0f), 2) + 3 * std::min(int(v * 3.0f), 2);
        return glass[cell % 6] * smoothStep(0.015f - edge, 0.015f + edge, d);
    }
    case LightTexture::Sign: {
        // Four 40x44-texel letters of 6-texel strokes on red, in a 256x64 sign.
        int px = int(x), py = int(y) - 10;
        int letter = (px - 24) / 56, lx = (px - 24) % 56;
        const glm::vec3 red(0.7f, 0.04f, 0.03f), lit(1.0f, 0.85f, 0.5f);
        if (px < 24 || letter > 3 || lx >= 40 || py < 0 || py >= 44) return red;
        const int t = 6, half = 22;
        uint8_t bits = kSignLetters[letter];
        bool left = lx < t, right = lx >= 40 - t;
        bool on = ((bits & 1) && py < t) || ((bits & 8) && py >= 44 - t) ||
                  ((bits & 64) && py >= half - t / 2 && py < half + t / 2) ||
                  ((bits & 32) && left && py < half) || ((bits & 2) && right && py < half) ||
                  ((bits & 16) && left && py >= half) || ((bits & 4) && right && py >= half);
        return on ? lit : red;
    }
    case LightTexture::Panel:
        return ((x / 4 + y / 4) % 2 == 0) ? glm::vec3(1.0f, 0.188f, 0.007f)
                                          : glm::vec3(1.0f, 0.578f, 0.021f);
    }
    return glm::vec3(1.0f);
}

// A one-sided textured area light of `size` (along right, along up = cross(normal, right))
// emitting `radiance` x its texture toward `normal`, with an emissive quad of the same texture
// just behind it so the emitter is seen.
Light addAreaLight(Scene& scene, const std::string& name, glm::vec3 centre, glm::vec3 right,
                   glm::vec3 normal, glm::vec2 size, int32_t texture, glm::vec3 radiance,
                   float range) {
    Material m;
    m.name = name + " emitter";
    m.baseColorFactor = glm::vec4(0.02f, 0.02f, 0.02f, 1.0f);
    m.roughnessFactor = 0.9f;
    m.emissiveFactor = radiance;
    m.emissiveTexture = texture;
    scene.materials.push_back(m);
    Mesh quad = makePlane(name, size.x, size.y, uint32_t(scene.materials.size() - 1));
    for (Vertex& v : quad.vertices) { // the texture across the quad, top row up
        v.uv0 = glm::vec2(v.position.x / size.x + 0.5f, v.position.z / size.y + 0.5f);
        v.uv1 = v.uv0;
    }
    scene.meshes.push_back(quad);
    glm::vec3 up = glm::cross(normal, right);
    Instance inst;
    inst.name = name;
    inst.mesh = uint32_t(scene.meshes.size() - 1);
    // Plane x -> right, y (its normal) -> normal, z -> -up: a rotation, so it stays CCW.
    inst.transform = glm::mat4(glm::vec4(right, 0.0f), glm::vec4(normal, 0.0f),
                               glm::vec4(-up, 0.0f), glm::vec4(centre - normal * 0.01f, 1.0f));
    scene.instances.push_back(inst);
    Light l = light(LightType::Area, name, centre, glm::vec3(1.0f), 1.0f, range);
    l.color = radiance;
    l.direction = normal;
    l.axis = right;
    l.areaSize = size;
    l.texture = texture;
    return l;
}

// A spot projecting `texture` (a gobo) from `position` toward `target`, its right axis
// horizontal.
Light goboSpot(LightType type, const std::string& name, glm::vec3 position, glm::vec3 target,
               glm::vec3 color, float intensity, float range, int32_t texture) {
    Light l = light(type, name, position, color, intensity, range);
    l.direction = glm::normalize(target - position);
    glm::vec3 side = glm::cross(l.direction, glm::vec3(0, 1, 0));
    l.axis = glm::length(side) > 1e-3f ? glm::normalize(side) : glm::vec3(1, 0, 0);
    l.innerConeAngle = 0.38f;
    l.outerConeAngle = 0.45f;
    l.texture = texture;
    return l;
}

} // namespace

int32_t addLightTexture(Scene& scene, LightTexture kind) {
    Texture t;
    const char* names[] = {"gobo window", "gobo stained glass", "sign", "panel"};
    t.name = names[int(kind)];
    t.width = kind == LightTexture::Sign ? 256 : kind == LightTexture::Panel ? 64 : 128;
    t.height = kind == LightTexture::Sign ? 64 : t.width;
    t.srgb = true;
    t.rgba8.resize(size_t(t.width) * t.height * 4);
    for (uint32_t y = 0; y < t.height; ++y)
        for (uint32_t x = 0; x < t.width; ++x) {
            glm::vec3 c = lightTexel(kind, x, y, t.width, t.height);
            uint8_t* p = &t.rgba8[(size_t(y) * t.width + x) * 4];
            for (int k = 0; k < 3; ++k) p[k] = uint8_t(srgbEncode(c[k]) * 255.0f + 0.5f);
            p[3] = 255;
        }
    scene.textures.push_back(std::move(t));
    return int32_t(scene.textures.size() - 1);
}

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
    scene.environment = Scene::Environment::Hemisphere; // lit as authored, not by a day sky
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

namespace {

// builtin:lights' textured lights: shop signs (textured area lights) and gobo spots,
// half along the avenue before the night camera, half on the streets. Their own generator,
// so the lights before them are the same as without them.
void addStreetTexturedLights(Scene& scene) {
    Rng rng{0x7E47u};
    int32_t window = addLightTexture(scene, LightTexture::Window);
    int32_t glass = addLightTexture(scene, LightTexture::StainedGlass);
    int32_t sign = addLightTexture(scene, LightTexture::Sign);
    int32_t panel = addLightTexture(scene, LightTexture::Panel);
    for (int i = 0; i < 8; ++i) { // signs over the avenue's north side, facing it
        glm::vec3 at{-50.0f + 4.0f * float(i), 3.4f, 6.2f};
        scene.lights.push_back(addAreaLight(scene, "avenue sign " + std::to_string(i), at,
                                            {-1, 0, 0}, {0, 0, -1}, {1.6f, 0.4f}, sign,
                                            glm::vec3(rng.uniform(3.0f, 6.0f)), 7.0f));
    }
    for (int i = 0; i < 8; ++i) { // panels over street corners, facing along a street
        float along = rng.uniform(-50.0f, 50.0f);
        float across = 7.5f + 15.0f * float(rng.range(-4, 3));
        bool alongX = rng.range(0, 1) != 0;
        glm::vec3 at = alongX ? glm::vec3(along, 3.0f, across) : glm::vec3(across, 3.0f, along);
        glm::vec3 normal = alongX ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0);
        if (rng.range(0, 1)) normal = -normal;
        glm::vec3 right = glm::cross(glm::vec3(0, 1, 0), normal);
        scene.lights.push_back(addAreaLight(scene, "street panel " + std::to_string(i), at, right,
                                            normal, {1.0f, 1.2f}, panel,
                                            glm::vec3(rng.uniform(3.0f, 6.0f)), 6.0f));
    }
    for (int i = 0; i < 16; ++i) { // gobos: 8 down the avenue, 8 over the streets
        glm::vec3 at = i < 8 ? glm::vec3(-49.0f + 4.0f * float(i), 5.5f, rng.uniform(-1.0f, 1.0f))
                             : glm::vec3(7.5f + 15.0f * float(rng.range(-4, 3)), 5.5f,
                                         rng.uniform(-50.0f, 50.0f));
        glm::vec3 target =
            at + glm::vec3(rng.uniform(-1.5f, 1.5f), -5.5f, rng.uniform(-1.5f, 1.5f));
        Light l = goboSpot(i % 2 ? LightType::SquareSpot : LightType::Spot,
                           "gobo " + std::to_string(i), at, target, warmOrCool(rng),
                           rng.uniform(25.0f, 45.0f), 9.0f, i % 3 == 0 ? glass : window);
        l.textureTiling = i % 4 == 1 ? 2.0f : 1.0f;
        scene.lights.push_back(l);
    }
}

} // namespace

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
    scene.environment = Scene::Environment::Hemisphere; // lit as authored, not by a day sky

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
    addStreetTexturedLights(scene);
    return scene;
}

Scene makeTexturedLightsScene() {
    Scene scene;
    scene.name = "textured-lights";
    scene.skyColor = glm::vec3(0.01f, 0.012f, 0.02f);
    scene.ambientColor = glm::vec3(0.015f, 0.015f, 0.018f);
    scene.environment = Scene::Environment::Hemisphere; // lit as authored, not by a day sky
    uint32_t floor = addMaterial(scene, "floor", {0.5f, 0.5f, 0.5f}, 0.8f);
    uint32_t wall = addMaterial(scene, "wall", {0.7f, 0.7f, 0.7f}, 0.75f);
    uint32_t housing = addMaterial(scene, "panel housing", {0.05f, 0.05f, 0.05f}, 0.5f);
    scene.meshes.push_back(makePlane("floor", 14.0f, 12.0f, floor, 4));
    scene.instances.push_back({"floor", uint32_t(scene.meshes.size() - 1), glm::mat4(1.0f)});
    addBox(scene, "back wall", {12.0f, 4.5f, 0.2f}, {0.0f, 0.0f, -3.0f}, wall); // face z = -2.9
    addBox(scene, "side wall", {0.2f, 4.5f, 8.0f}, {-5.0f, 0.0f, 1.0f}, wall);  // face x = -4.9
    int32_t window = addLightTexture(scene, LightTexture::Window);
    int32_t glass = addLightTexture(scene, LightTexture::StainedGlass);
    int32_t sign = addLightTexture(scene, LightTexture::Sign);
    int32_t panel = addLightTexture(scene, LightTexture::Panel);
    // Gobos: a window on the back wall (round cone), stained glass on the floor (square cone).
    scene.lights.push_back(goboSpot(LightType::Spot, "window gobo", {2.0f, 3.8f, 0.5f},
                                    {2.2f, 1.7f, -2.9f}, {1.0f, 0.95f, 0.9f}, 40.0f, 12.0f,
                                    window));
    Light stained = goboSpot(LightType::SquareSpot, "stained glass gobo", {-1.5f, 4.0f, 2.5f},
                             {-1.2f, 0.0f, 0.5f}, {1.0f, 1.0f, 1.0f}, 35.0f, 10.0f, glass);
    stained.outerConeAngle = 0.5f;
    stained.innerConeAngle = 0.44f;
    scene.lights.push_back(stained);
    // Area lights: the shop sign high on the back wall over the floor (its range stops short of
    // the side wall), the panel facing the side wall (1.7 m from it) in a dark housing.
    scene.lights.push_back(addAreaLight(scene, "shop sign", {-1.0f, 3.3f, -2.88f}, {1, 0, 0},
                                        {0, 0, 1}, {2.4f, 0.6f}, sign, glm::vec3(6.0f), 4.5f));
    scene.lights.push_back(addAreaLight(scene, "panel", {-3.2f, 1.6f, 0.5f}, {0, 0, 1}, {-1, 0, 0},
                                        {1.2f, 1.6f}, panel, glm::vec3(8.0f), 8.0f));
    addBox(scene, "panel housing", {0.04f, 1.7f, 1.3f}, {-3.16f, 0.75f, 0.5f}, housing);
    // A string of small lamps along the top of the back wall: with them the frame has enough
    // lights in view for tiled culling (render/lighting/light_culling.cpp).
    for (int i = 0; i < 16; ++i)
        scene.lights.push_back(light(LightType::Point, "string lamp " + std::to_string(i),
                                     {-4.5f + 0.6f * float(i), 4.2f, -2.6f}, {1.0f, 0.8f, 0.55f},
                                     0.6f, 2.0f));
    // The moon, dim, from the right: it does not reach the side wall (the area light test's).
    Light moon;
    moon.name = "moon";
    moon.type = LightType::Directional;
    moon.direction = glm::normalize(glm::vec3(0.3f, -1.0f, -0.4f));
    moon.color = {0.6f, 0.7f, 1.0f};
    moon.intensity = 0.05f;
    moon.castsShadow = true;
    scene.lights.push_back(moon);
    Camera main;
    main.name = "main";
    main.position = {1.0f, 1.7f, 7.0f};
    main.forward = glm::normalize(glm::vec3(-0.5f, 1.4f, -2.0f) - main.position);
    main.up = glm::normalize(glm::vec3(0, 1, 0) - main.forward * main.forward.y);
    main.yfov = 0.9f;
    main.znear = 0.1f;
    main.zfar = 60.0f;
    scene.cameras.push_back(main);
    return scene;
}

} // namespace shadel
