#include "scene/builtin_scenes.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"
#include "core/log.h"
#include "scene/builtin_decals.h"
#include "scene/builtin_gallery.h"
#include "scene/builtin_lights.h"
#include "scene/builtin_materials.h"
#include "scene/mesh_utils.h"

namespace shadel {

namespace {

// splitmix64: our own generator so the scenes are identical on every platform and standard
// library (std:: distributions are implementation-defined).
class Rng {
public:
    explicit Rng(uint64_t seed) : state_(seed) {}
    uint64_t next() {
        uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    float uniform(float lo, float hi) {
        return lo + (hi - lo) * float(next() >> 40) / float(1ull << 24);
    }
    int range(int lo, int hi) { return lo + int(next() % uint64_t(hi - lo + 1)); } // inclusive
    bool chance(float p) { return uniform(0.0f, 1.0f) < p; }

private:
    uint64_t state_;
};

// Small helpers to keep the scene descriptions below readable.
class SceneBuilder {
public:
    explicit SceneBuilder(Scene& scene) : scene_(scene) {}

    uint32_t material(const std::string& name, glm::vec3 color, float roughness,
                      float metallic = 0.0f, Procedural procedural = Procedural::None,
                      float proceduralScale = 1.0f, glm::vec3 emissive = glm::vec3(0.0f)) {
        Material m;
        m.name = name;
        m.baseColorFactor = glm::vec4(color, 1.0f);
        m.roughnessFactor = roughness;
        m.metallicFactor = metallic;
        m.procedural = procedural;
        m.proceduralScale = proceduralScale;
        m.emissiveFactor = emissive;
        scene_.materials.push_back(m);
        return uint32_t(scene_.materials.size() - 1);
    }

    uint32_t mesh(Mesh m) {
        scene_.meshes.push_back(std::move(m));
        return uint32_t(scene_.meshes.size() - 1);
    }

    // Rigid placement only (translation + rotation about Y): mesh UVs are in metres, and the
    // shadel parametrisation relies on object-space area matching world-space area.
    void place(const std::string& name, uint32_t mesh, glm::vec3 position, float yaw = 0.0f) {
        Instance inst;
        inst.name = name;
        inst.mesh = mesh;
        inst.transform =
            glm::rotate(glm::translate(glm::mat4(1.0f), position), yaw, glm::vec3(0, 1, 0));
        scene_.instances.push_back(std::move(inst));
    }

    // Box resting on y = base (mesh is centred, so lift by half the height).
    void box(const std::string& name, glm::vec3 size, uint32_t material, glm::vec3 footprint,
             float yaw = 0.0f) {
        uint32_t m = mesh(makeBox(name, size, material));
        place(name, m, footprint + glm::vec3(0, size.y * 0.5f, 0), yaw);
    }

    void camera(const std::string& name, glm::vec3 position, glm::vec3 target, float yfov = 0.8f,
                float znear = 0.1f, float zfar = 400.0f) {
        Camera c;
        c.name = name;
        c.position = position;
        c.forward = glm::normalize(target - position);
        glm::vec3 up = glm::vec3(0, 1, 0) - c.forward * glm::dot(glm::vec3(0, 1, 0), c.forward);
        c.up = glm::normalize(up);
        c.yfov = yfov;
        c.znear = znear;
        c.zfar = zfar;
        scene_.cameras.push_back(c);
    }

    void sun(glm::vec3 direction, float intensity, glm::vec3 color = {1.0f, 0.96f, 0.9f}) {
        Light l;
        l.name = "sun";
        l.type = LightType::Directional;
        l.direction = glm::normalize(direction);
        l.intensity = intensity;
        l.color = color;
        l.castsShadow = true;
        scene_.lights.push_back(l);
    }

    void pointLight(const std::string& name, glm::vec3 position, glm::vec3 color, float intensity,
                    float range) {
        Light l;
        l.name = name;
        l.type = LightType::Point;
        l.position = position;
        l.color = color;
        l.intensity = intensity;
        l.range = range;
        scene_.lights.push_back(l);
    }

    void spotLight(const std::string& name, glm::vec3 position, glm::vec3 target, glm::vec3 color,
                   float intensity, float range, float inner, float outer) {
        Light l;
        l.name = name;
        l.type = LightType::Spot;
        l.position = position;
        l.direction = glm::normalize(target - position);
        l.color = color;
        l.intensity = intensity;
        l.range = range;
        l.innerConeAngle = inner;
        l.outerConeAngle = outer;
        scene_.lights.push_back(l);
    }

private:
    Scene& scene_;
};

const glm::vec3 kDefaultLampSpots[6] = {{-9, 0, 9}, {9, 0, 9},  {-9, 0, -9},
                                        {9, 0, -9}, {0, 0, 18}, {-18, 0, 0}};
const glm::vec3 kDefaultTable{3.0f, 0.0f, 8.0f};

// The default scene's materials, created in this order (material indices are part of what the
// tests' reference images show).
struct DefaultMaterials {
    uint32_t asphalt, plazaChecker, wallChecker, bricks, darkBricks, concrete[4], roofGrey, steel,
        lampGlass, wood, barrelRed, stone, plastic[4], chrome;
};

DefaultMaterials makeDefaultMaterials(SceneBuilder& b) {
    DefaultMaterials m;
    m.asphalt = b.material("asphalt", {0.22f, 0.22f, 0.24f}, 0.92f);
    m.plazaChecker = b.material("plaza checker", {0.85f, 0.85f, 0.82f}, 0.6f, 0.0f,
                                Procedural::TexelChecker, 20.0f); // 5 cm cells
    m.wallChecker = b.material("wall checker", {0.9f, 0.9f, 0.9f}, 0.5f, 0.0f,
                               Procedural::TexelChecker, 32.0f); // ~3 cm cells
    m.bricks = b.material("bricks", {0.62f, 0.28f, 0.2f}, 0.85f, 0.0f, Procedural::Bricks, 4.0f);
    m.darkBricks =
        b.material("dark bricks", {0.4f, 0.22f, 0.18f}, 0.9f, 0.0f, Procedural::Bricks, 3.0f);
    const uint32_t concrete[4] = {
        b.material("concrete", {0.7f, 0.68f, 0.62f}, 0.8f),
        b.material("blue render", {0.5f, 0.57f, 0.65f}, 0.7f),
        b.material("sandstone", {0.8f, 0.72f, 0.55f}, 0.85f),
        b.material("slate", {0.4f, 0.41f, 0.45f}, 0.6f),
    };
    m.roofGrey = b.material("roof units", {0.55f, 0.55f, 0.55f}, 0.5f, 0.6f);
    m.steel = b.material("steel", {0.85f, 0.86f, 0.88f}, 0.3f, 1.0f);
    m.lampGlass = b.material("lamp globe", {1.0f, 0.95f, 0.85f}, 0.2f, 0.0f, Procedural::None, 1.0f,
                             {4.0f, 3.2f, 2.2f});
    m.wood = b.material("wood", {0.55f, 0.38f, 0.22f}, 0.7f);
    m.barrelRed = b.material("barrel paint", {0.6f, 0.08f, 0.06f}, 0.45f, 0.3f);
    m.stone = b.material("stone", {0.62f, 0.6f, 0.58f}, 0.75f);
    const uint32_t plastic[4] = {
        b.material("red plastic", {0.8f, 0.1f, 0.08f}, 0.35f),
        b.material("yellow plastic", {0.9f, 0.75f, 0.1f}, 0.4f),
        b.material("blue plastic", {0.1f, 0.25f, 0.8f}, 0.3f),
        b.material("green plastic", {0.15f, 0.6f, 0.2f}, 0.45f),
    };
    m.chrome = b.material("chrome", {0.95f, 0.93f, 0.9f}, 0.1f, 1.0f);

    std::copy(std::begin(concrete), std::end(concrete), m.concrete);
    std::copy(std::begin(plastic), std::end(plastic), m.plastic);
    return m;
}

// Buildings on a 15 m lot grid around an open centre of 45 m x 45 m, with an avenue along X.
void addDefaultBuildings(SceneBuilder& b, Rng& rng, const DefaultMaterials& m) {
    int buildingCount = 0;
    for (int gz = -3; gz <= 3; ++gz) {
        for (int gx = -3; gx <= 3; ++gx) {
            if (std::abs(gx) <= 1 && std::abs(gz) <= 1) continue;
            if (gz == 0) continue; // an avenue along X through the plaza (the "street" camera)
            if (!rng.chance(0.85f)) continue;
            glm::vec3 size{rng.uniform(6.0f, 12.0f), 0.0f, rng.uniform(6.0f, 12.0f)};
            // Mostly low, a few towers: heights spread over 4 m .. 40 m.
            float t = rng.uniform(0.0f, 1.0f);
            size.y = 4.0f + 36.0f * t * t * t;
            glm::vec3 lot{gx * 15.0f + rng.uniform(-1.0f, 1.0f), 0.0f,
                          gz * 15.0f + rng.uniform(-1.0f, 1.0f)};
            float r = rng.uniform(0.0f, 1.0f);
            uint32_t mat = r < 0.25f   ? m.bricks
                           : r < 0.35f ? m.darkBricks
                                       : m.concrete[rng.range(0, 3)];
            std::string name = "building " + std::to_string(buildingCount++);
            b.box(name, size, mat, lot);
            int roofUnits = rng.range(0, 3);
            for (int u = 0; u < roofUnits; ++u) {
                glm::vec3 unit{rng.uniform(0.8f, 2.5f), rng.uniform(0.6f, 2.0f),
                               rng.uniform(0.8f, 2.5f)};
                glm::vec3 at = lot + glm::vec3(rng.uniform(-0.3f, 0.3f) * (size.x - unit.x), size.y,
                                               rng.uniform(-0.3f, 0.3f) * (size.z - unit.z));
                b.box(name + " roof unit " + std::to_string(u), unit, m.roofGrey, at,
                      rng.uniform(0.0f, 0.3f));
            }
        }
    }
}

// Pillars around the plaza, lamp posts with glowing globes, benches, crates, barrels and
// decorative spheres.
void addDefaultProps(SceneBuilder& b, Rng& rng, const DefaultMaterials& m) {
    const float pi = glm::pi<float>();
    uint32_t pillar = b.mesh(makeCylinder("pillar", 0.45f, 6.0f, m.stone));
    for (int i = 0; i < 8; ++i) {
        float a = 2.0f * pi * (float(i) + 0.5f) / 8.0f;
        b.place("pillar " + std::to_string(i), pillar,
                {std::cos(a) * 11.5f, 0.0f, std::sin(a) * 11.5f});
    }
    uint32_t post = b.mesh(makeCylinder("lamp post", 0.08f, 5.0f, m.steel, 12));
    uint32_t globe = b.mesh(makeSphere("lamp globe", 0.22f, m.lampGlass, 16, 8));
    for (int i = 0; i < 6; ++i) {
        b.place("lamp post " + std::to_string(i), post, kDefaultLampSpots[i]);
        b.place("lamp globe " + std::to_string(i), globe,
                kDefaultLampSpots[i] + glm::vec3(0, 5.2f, 0));
    }

    // Benches, crates, barrels and decorative spheres.
    for (int i = 0; i < 6; ++i) {
        float a = 2.0f * pi * float(i) / 6.0f;
        b.box("bench " + std::to_string(i), {2.0f, 0.45f, 0.5f}, m.wood,
              {std::cos(a) * 9.5f, 0.0f, std::sin(a) * 9.5f}, -a + pi * 0.5f);
    }
    for (int i = 0; i < 20; ++i) {
        float s = rng.uniform(0.45f, 1.0f);
        glm::vec3 at{rng.uniform(-20.0f, -12.0f), 0.0f, rng.uniform(-20.0f, 20.0f)};
        b.box("crate " + std::to_string(i), glm::vec3(s), m.wood, at, rng.uniform(0.0f, pi));
        if (rng.chance(0.3f)) {
            float s2 = s * rng.uniform(0.5f, 0.9f);
            b.box("crate " + std::to_string(i) + " top", glm::vec3(s2), m.wood,
                  at + glm::vec3(0, s, 0), rng.uniform(0.0f, pi));
        }
    }
    uint32_t barrel = b.mesh(makeCylinder("barrel", 0.3f, 0.9f, m.barrelRed, 20));
    for (int i = 0; i < 12; ++i)
        b.place("barrel " + std::to_string(i), barrel,
                {rng.uniform(12.0f, 20.0f), 0.0f, rng.uniform(-20.0f, 20.0f)},
                rng.uniform(0.0f, pi));
    for (int i = 0; i < 10; ++i) {
        float r = rng.uniform(0.3f, 1.5f);
        uint32_t mat = i % 3 == 0 ? m.chrome : m.plastic[rng.range(0, 3)];
        uint32_t m = b.mesh(makeSphere("ball " + std::to_string(i), r, mat, 32, 16));
        b.place("ball " + std::to_string(i), m,
                {rng.uniform(-7.0f, 7.0f), r + 0.05f, rng.uniform(-7.0f, 7.0f)});
    }
}

// A table near the main camera covered with objects of a few centimetres, and pebbles and tiny
// debris on the ground around the plaza.
void addDefaultSmallObjects(SceneBuilder& b, Rng& rng, const DefaultMaterials& m) {
    const float pi = glm::pi<float>();
    const glm::vec3 table = kDefaultTable;
    b.box("table top", {1.6f, 0.05f, 0.9f}, m.wood, table + glm::vec3(0, 0.72f, 0));
    uint32_t leg = b.mesh(makeCylinder("table leg", 0.03f, 0.72f, m.steel, 10));
    for (int i = 0; i < 4; ++i)
        b.place("table leg " + std::to_string(i), leg,
                table + glm::vec3((i & 1) ? 0.72f : -0.72f, 0, (i & 2) ? 0.38f : -0.38f));
    std::vector<uint32_t> tinyBoxes, tinySpheres;
    for (int i = 0; i < 4; ++i) {
        float s = 0.02f + 0.015f * float(i);
        tinyBoxes.push_back(
            b.mesh(makeBox("tiny box " + std::to_string(i), glm::vec3(s), m.plastic[i])));
        tinySpheres.push_back(
            b.mesh(makeSphere("tiny sphere " + std::to_string(i), 0.01f + 0.01f * float(i),
                              i % 2 ? m.chrome : m.plastic[(i + 2) % 4], 12, 6)));
    }
    for (int i = 0; i < 30; ++i) {
        int k = rng.range(0, 3);
        glm::vec3 at =
            table + glm::vec3(rng.uniform(-0.7f, 0.7f), 0.745f, rng.uniform(-0.38f, 0.38f));
        if (i % 2 == 0) {
            float s = 0.02f + 0.015f * float(k);
            b.place("table box " + std::to_string(i), tinyBoxes[size_t(k)],
                    at + glm::vec3(0, s * 0.5f, 0), rng.uniform(0.0f, pi));
        } else {
            b.place("table sphere " + std::to_string(i), tinySpheres[size_t(k)],
                    at + glm::vec3(0, 0.01f + 0.01f * float(k), 0));
        }
    }
    // Pebbles and tiny debris on the ground around the plaza.
    std::vector<uint32_t> pebbles;
    for (int i = 0; i < 4; ++i)
        pebbles.push_back(b.mesh(
            makeSphere("pebble " + std::to_string(i), 0.02f + 0.012f * float(i), m.stone, 10, 5)));
    for (int i = 0; i < 100; ++i) {
        int k = rng.range(0, 3);
        glm::vec3 at{rng.uniform(-10.0f, 10.0f), 0.0f, rng.uniform(6.0f, 16.0f)};
        if (i % 3 == 0) {
            float s = 0.02f + 0.015f * float(k);
            b.place("debris " + std::to_string(i), tinyBoxes[size_t(k)],
                    at + glm::vec3(0, s * 0.5f, 0), rng.uniform(0.0f, pi));
        } else {
            b.place("pebble " + std::to_string(i), pebbles[size_t(k)],
                    at + glm::vec3(0, 0.02f + 0.012f * float(k), 0));
        }
    }
}

// Lights: sun, warm street lamps, a cool accent, spots on the checker wall, a facade, the table;
// and the cameras.
void addDefaultLightsAndCameras(SceneBuilder& b) {
    const glm::vec3 table = kDefaultTable;
    b.sun({-0.45f, -1.0f, -0.3f}, 3.0f);
    for (int i = 0; i < 4; ++i)
        b.pointLight("lamp " + std::to_string(i), kDefaultLampSpots[i] + glm::vec3(0, 4.9f, 0),
                     {1.0f, 0.8f, 0.55f}, 40.0f, 14.0f);
    b.pointLight("blue accent", {-16.0f, 1.5f, -16.0f}, {0.4f, 0.6f, 1.0f}, 25.0f, 10.0f);
    b.spotLight("wall spot", {0.0f, 6.0f, -5.0f}, {0.0f, 2.5f, -14.0f}, {1.0f, 0.97f, 0.9f}, 300.0f,
                25.0f, 0.35f, 0.55f);
    b.spotLight("facade spot", {-20.0f, 0.5f, 22.0f}, {-30.0f, 10.0f, 30.0f}, {1.0f, 0.85f, 0.7f},
                400.0f, 40.0f, 0.25f, 0.45f);
    b.spotLight("table spot", table + glm::vec3(0.5f, 3.5f, 0.5f), table + glm::vec3(0, 0.75f, 0),
                {1.0f, 1.0f, 1.0f}, 80.0f, 8.0f, 0.3f, 0.5f);

    // Main: between two pillars towards the checker wall, over the checker plaza, with the table
    // of tiny objects in the near right.
    b.camera("main", {1.5f, 1.7f, 17.0f}, {-0.5f, 1.2f, -10.0f});
    b.camera("overview", {60.0f, 50.0f, 60.0f}, {0.0f, 0.0f, 0.0f}, 0.8f, 0.5f, 400.0f);
    b.camera("street", {-52.0f, 1.6f, 2.0f}, {0.0f, 3.0f, -1.0f});
}

// A small city block around a plaza: one large ground, tens of buildings, props, and a hundred
// or so objects of a few centimetres, lit by a sun, street lamps and spots. The parts draw from
// one random sequence in this order.
Scene makeDefault() {
    Scene scene;
    scene.name = "default";
    SceneBuilder b(scene);
    Rng rng(0x5ADE1D0001ull);
    const DefaultMaterials m = makeDefaultMaterials(b);
    // Ground and the high-frequency surfaces.
    b.place("ground", b.mesh(makePlane("ground", 120.0f, 120.0f, m.asphalt, 12)), {0, 0, 0});
    b.box("checker plaza", {16.0f, 0.05f, 16.0f}, m.plazaChecker, {0, 0, 0});
    b.box("checker wall", {12.0f, 5.0f, 0.3f}, m.wallChecker, {0, 0, -14.0f});

    addDefaultBuildings(b, rng, m);
    addDefaultProps(b, rng, m);
    addDefaultSmallObjects(b, rng, m);
    addDefaultLightsAndCameras(b);
    return scene;
}

// A huge one-texel checker seen at a grazing angle: the aliasing test.
Scene makeChecker() {
    Scene scene;
    scene.name = "checker";
    SceneBuilder b(scene);
    uint32_t checker =
        b.material("checker", {0.85f, 0.85f, 0.85f}, 0.7f, 0.0f, Procedural::TexelChecker,
                   20.0f); // 5 cm cells
    b.place("checker plane", b.mesh(makePlane("checker plane", 200.0f, 200.0f, checker, 20)),
            {0, 0, 0});
    b.sun({-0.3f, -1.0f, -0.5f}, 3.0f);
    // 1.5 m above the plane, looking 7 degrees down: the ground fills the lower half of the view
    // out to the horizon.
    const float pitch = glm::radians(7.0f);
    glm::vec3 eye{0.0f, 1.5f, 95.0f};
    b.camera("main", eye, eye + glm::vec3(0.0f, -std::sin(pitch), -std::cos(pitch)), 0.8f, 0.1f,
             400.0f);
    const float lowPitch = glm::radians(4.0f);
    b.camera("low", eye, eye + glm::vec3(0.3f, -std::sin(lowPitch), -std::cos(lowPitch)), 0.8f,
             0.1f, 400.0f);
    return scene;
}

// Only low-frequency materials: for comparing shading paths where aliasing must not dominate.
Scene makeSmooth() {
    Scene scene;
    scene.name = "smooth";
    SceneBuilder b(scene);
    uint32_t ground = b.material("ground", {0.6f, 0.6f, 0.58f}, 0.9f);
    uint32_t red = b.material("matte red", {0.75f, 0.15f, 0.12f}, 0.6f);
    uint32_t gold = b.material("gold", {1.0f, 0.78f, 0.34f}, 0.35f, 1.0f);
    uint32_t white = b.material("white", {0.85f, 0.85f, 0.85f}, 0.8f);
    uint32_t blue = b.material("blue", {0.2f, 0.35f, 0.75f}, 0.5f);
    uint32_t green = b.material("green", {0.25f, 0.6f, 0.3f}, 0.7f);
    uint32_t orange = b.material("orange", {0.9f, 0.45f, 0.1f}, 0.4f);
    uint32_t silver = b.material("silver", {0.9f, 0.9f, 0.92f}, 0.5f, 1.0f);

    b.place("ground", b.mesh(makePlane("ground", 40.0f, 40.0f, ground, 4)), {0, 0, 0});
    b.place("red sphere", b.mesh(makeSphere("red sphere", 1.0f, red, 48, 24)), {-2.5f, 1.0f, 0.0f});
    b.place("gold sphere", b.mesh(makeSphere("gold sphere", 0.6f, gold, 48, 24)),
            {0.2f, 0.6f, 1.5f});
    b.place("white sphere", b.mesh(makeSphere("white sphere", 1.5f, white, 48, 24)),
            {3.0f, 1.5f, -2.5f});
    b.box("blue box", {2.0f, 2.0f, 2.0f}, blue, {0.5f, 0.0f, -2.0f}, 0.5f);
    b.box("green tower", {1.0f, 3.0f, 1.0f}, green, {-4.5f, 0.0f, -3.0f}, 0.2f);
    b.place("orange cylinder", b.mesh(makeCylinder("orange cylinder", 0.5f, 2.0f, orange, 40)),
            {2.8f, 0, 1.8f});
    b.place("silver cylinder", b.mesh(makeCylinder("silver cylinder", 0.35f, 1.2f, silver, 40)),
            {-1.0f, 0, 2.5f});

    b.sun({-0.5f, -1.0f, -0.35f}, 3.0f);
    b.pointLight("warm", {-3.0f, 3.0f, 3.0f}, {1.0f, 0.75f, 0.5f}, 30.0f, 15.0f);
    b.pointLight("cool", {4.0f, 2.5f, 2.0f}, {0.5f, 0.7f, 1.0f}, 20.0f, 12.0f);
    b.camera("main", {0.0f, 3.0f, 9.5f}, {0.0f, 0.8f, 0.0f}, 0.8f, 0.1f, 100.0f);
    b.camera("side", {-9.0f, 2.0f, 3.0f}, {0.0f, 1.0f, 0.0f}, 0.8f, 0.1f, 100.0f);
    return scene;
}

// A city block grid for scaling tests (GPU culling, LODs, occlusion): `instances` instances in
// all (the ground, then blocks of four buildings and twelve street props: trees, lamp posts,
// cars). The camera stands at street level near the centre, so buildings hide most blocks.
// The tree and lamp meshes are finely tessellated on purpose: LOD selection has work to do.
Scene makeMany(uint32_t instances) {
    Scene scene;
    scene.name = "many";
    SceneBuilder b(scene);
    Rng rng(0x5ADE1D0004ull);
    uint32_t ground = b.material("asphalt", {0.32f, 0.32f, 0.34f}, 0.9f);
    const glm::vec3 facade[3] = {{0.75f, 0.68f, 0.6f}, {0.55f, 0.6f, 0.7f}, {0.7f, 0.45f, 0.4f}};
    const float height[3] = {12.0f, 21.0f, 34.0f};
    std::vector<uint32_t> buildings;
    for (int i = 0; i < 3; ++i) {
        uint32_t mat = b.material("facade " + std::to_string(i), facade[i], 0.8f);
        buildings.push_back(b.mesh(
            makeBox("building " + std::to_string(i), glm::vec3(13.0f, height[i], 13.0f), mat)));
    }
    uint32_t leaves = b.material("leaves", {0.22f, 0.5f, 0.2f}, 0.7f);
    uint32_t metal = b.material("lamp metal", {0.25f, 0.25f, 0.27f}, 0.35f, 1.0f);
    uint32_t paint = b.material("car paint", {0.8f, 0.15f, 0.1f}, 0.3f);
    uint32_t tree = b.mesh(makeSphere("tree", 2.0f, leaves, 32, 16));
    uint32_t lamp = b.mesh(makeCylinder("lamp post", 0.15f, 6.0f, metal, 24));
    uint32_t car = b.mesh(makeBox("car", glm::vec3(4.0f, 1.4f, 1.9f), paint));

    constexpr uint32_t kPerBlock = 16; // 4 buildings + 12 props
    constexpr float kPitch = 40.0f;    // 30 m blocks, 10 m streets
    constexpr float kBuildingSink = 0.1f;
    uint32_t rest = instances > 0 ? instances - 1 : 0;
    uint32_t blocks = (rest + kPerBlock - 1) / kPerBlock;
    uint32_t side = std::max(1u, uint32_t(std::ceil(std::sqrt(double(blocks)))));
    float extent = float(side) * kPitch;
    b.place("ground", b.mesh(makePlane("ground", extent + 40.0f, extent + 40.0f, ground, 8)),
            {0, 0, 0});
    auto origin = [&](uint32_t i) { return (float(i) - 0.5f * float(side - 1)) * kPitch; };
    uint32_t placed = 0;
    for (uint32_t k = 0; k < blocks; ++k) {
        glm::vec3 centre(origin(k % side), 0.0f, origin(k / side));
        for (uint32_t j = 0; j < kPerBlock && placed < rest; ++j, ++placed) {
            if (j < 4) { // a 2 x 2 lot of buildings, 1 m passages between them
                glm::vec3 lot((j & 1) ? 7.0f : -7.0f, 0.0f, (j & 2) ? 7.0f : -7.0f);
                int kind = rng.range(0, 2);
                // Sunk 10 cm into the ground: a bottom face on the ground's plane z-fights
                // with it and shadows it with acne (seen when a camera path enters a building).
                b.place("", buildings[kind],
                        centre + lot + glm::vec3(0, height[kind] * 0.5f - kBuildingSink, 0),
                        rng.range(0, 3) * 1.5707964f);
                continue;
            }
            // Props on the pavement around the block, 17 m from its centre.
            int edge = rng.range(0, 3);
            float t = rng.uniform(-14.0f, 14.0f);
            glm::vec3 offset = edge == 0   ? glm::vec3(t, 0, -17.0f)
                               : edge == 1 ? glm::vec3(t, 0, 17.0f)
                               : edge == 2 ? glm::vec3(-17.0f, 0, t)
                                           : glm::vec3(17.0f, 0, t);
            float pick = rng.uniform(0.0f, 1.0f);
            if (pick < 0.45f)
                b.place("", tree, centre + offset + glm::vec3(0, 3.0f, 0));
            else if (pick < 0.75f)
                b.place("", lamp, centre + offset);
            else // cars park along the kerb, 3 m further out
                b.place("", car, centre + offset * (20.0f / 17.0f) + glm::vec3(0, 0.7f, 0),
                        edge < 2 ? 0.0f : 1.5707964f);
        }
    }
    b.sun({-0.4f, -1.0f, -0.3f}, 3.0f);
    for (int i = 0; i < 4; ++i)
        b.pointLight("light " + std::to_string(i),
                     {(i & 1) ? 25.0f : -25.0f, 3.0f, (i & 2) ? 25.0f : -25.0f},
                     {1.0f, 0.85f, 0.7f}, 60.0f, 20.0f);
    // A street through the centre of the grid (between two blocks), at eye height above a car.
    float street = (side % 2 == 0) ? 0.0f : -0.5f * kPitch;
    b.camera("main", {street, 4.0f, street + 3.0f}, {street + 60.0f, 2.0f, street + 140.0f}, 0.9f,
             0.2f, 800.0f);
    b.camera("overview", {0.0f, 150.0f + 0.6f * extent, 0.01f}, {0.0f, 0.0f, 0.0f}, 0.9f, 1.0f,
             400.0f + 1.5f * extent);
    return scene;
}

// A camera-facing card (sprite) or pane: the XY plane facing +Z, centred, uv in metres.
Mesh makeCard(const std::string& name, float width, float height, uint32_t material) {
    Mesh m;
    m.name = name;
    m.material = material;
    const float x = width * 0.5f, y = height * 0.5f;
    const glm::vec2 corners[4] = {{-x, -y}, {x, -y}, {x, y}, {-x, y}};
    for (glm::vec2 c : corners) {
        Vertex v;
        v.position = glm::vec3(c, 0.0f);
        v.normal = glm::vec3(0, 0, 1);
        v.tangent = glm::vec4(1, 0, 0, 1);
        v.uv0 = glm::vec2(c.x + x, y - c.y) / glm::vec2(width, height);
        v.uv1 = v.uv0;
        m.vertices.push_back(v);
    }
    m.indices = {0, 1, 2, 0, 2, 3};
    computeBounds(m);
    return m;
}

// A soft round puff (alpha falls off smoothly to 0 at the edge) for smoke and fire sprites.
Texture makePuffTexture() {
    Texture t;
    t.name = "puff";
    t.width = t.height = 64;
    t.srgb = true;
    for (uint32_t y = 0; y < t.height; ++y) {
        for (uint32_t x = 0; x < t.width; ++x) {
            float u = (float(x) + 0.5f) / 32.0f - 1.0f, v = (float(y) + 0.5f) / 32.0f - 1.0f;
            float r = std::min(std::sqrt(u * u + v * v), 1.0f);
            float a = (1.0f - r * r) * (1.0f - r * r);
            t.rgba8.insert(t.rgba8.end(), {255, 255, 255, uint8_t(a * 255.0f + 0.5f)});
        }
    }
    return t;
}

// Transparency: overlapping coloured glass panes, a glass sphere, a smoke column of
// alpha-blended sprites and a fire of additive ones, in front of opaque geometry. Blended
// materials carry an additiveness: 0 for glass and smoke, 1 for the fire's core, 0.6 for its
// outer flames.
Scene makeTransparency() {
    Scene scene;
    scene.name = "transparency";
    SceneBuilder b(scene);
    scene.textures.push_back(makePuffTexture());
    auto blended = [&](const std::string& name, glm::vec4 color, float roughness,
                       glm::vec3 emissive, float additiveness, int32_t texture) {
        uint32_t m =
            b.material(name, glm::vec3(color), roughness, 0.0f, Procedural::None, 1.0f, emissive);
        Material& mat = scene.materials[m];
        mat.baseColorFactor.a = color.a;
        mat.alphaMode = AlphaMode::Blend;
        mat.doubleSided = true;
        mat.additiveness = additiveness;
        mat.baseColorTexture = texture;
        return m;
    };
    uint32_t ground = b.material("ground", {0.55f, 0.55f, 0.52f}, 0.9f);
    // Smooth opaque materials only: forward and decoupled are compared on this scene, and
    // high-frequency opaque content (bricks: 32.6 dB) would hide what transparency adds.
    uint32_t wall = b.material("wall", {0.7f, 0.45f, 0.35f}, 0.8f);
    uint32_t red = b.material("matte red", {0.75f, 0.15f, 0.12f}, 0.6f);
    uint32_t blue = b.material("blue", {0.2f, 0.35f, 0.75f}, 0.5f);
    uint32_t redGlass = blended("red glass", {0.9f, 0.15f, 0.1f, 0.45f}, 0.15f, {}, 0.0f, -1);
    uint32_t greenGlass = blended("green glass", {0.15f, 0.8f, 0.2f, 0.4f}, 0.15f, {}, 0.0f, -1);
    uint32_t blueGlass = blended("blue glass", {0.15f, 0.3f, 0.95f, 0.5f}, 0.15f, {}, 0.0f, -1);
    uint32_t clearGlass = blended("clear glass", {0.8f, 0.95f, 1.0f, 0.25f}, 0.05f, {}, 0.0f, -1);
    uint32_t smoke = blended("smoke", {0.45f, 0.45f, 0.48f, 0.35f}, 1.0f, {}, 0.0f, 0);
    uint32_t fireCore =
        blended("fire core", {0.0f, 0.0f, 0.0f, 0.9f}, 1.0f, {3.0f, 1.4f, 0.35f}, 1.0f, 0);
    uint32_t flames =
        blended("flames", {0.2f, 0.05f, 0.0f, 0.6f}, 1.0f, {1.6f, 0.45f, 0.08f}, 0.6f, 0);

    b.place("ground", b.mesh(makePlane("ground", 30.0f, 30.0f, ground, 4)), {0, 0, 0});
    b.box("back wall", {12.0f, 4.0f, 0.4f}, wall, {0.0f, 0.0f, -3.5f});
    b.box("red block", {1.0f, 1.0f, 1.0f}, red, {-0.4f, 0.0f, -1.8f}, 0.4f);
    b.place("blue sphere", b.mesh(makeSphere("blue sphere", 0.5f, blue, 32, 16)),
            {0.9f, 0.5f, -1.6f});

    const glm::vec3 eye{0.0f, 1.7f, 6.0f};
    auto facingEye = [&](glm::vec3 p) { return std::atan2(eye.x - p.x, eye.z - p.z); };
    // Three panes overlapping in depth and on screen.
    const uint32_t paneMaterials[3] = {redGlass, greenGlass, blueGlass};
    for (int i = 0; i < 3; ++i) {
        std::string name = "glass pane " + std::to_string(i);
        glm::vec3 at{-1.3f + 0.65f * float(i), 1.0f, 0.8f - 0.7f * float(i)};
        b.place(name, b.mesh(makeCard(name, 1.2f, 1.6f, paneMaterials[i])), at,
                0.25f * float(i - 1));
    }
    b.place("glass sphere", b.mesh(makeSphere("glass sphere", 0.55f, clearGlass, 32, 16)),
            {1.5f, 0.55f, 0.9f});
    // Smoke column: sprites rising and growing, drifting sideways.
    for (int i = 0; i < 10; ++i) {
        float t = float(i) / 9.0f;
        glm::vec3 at{-2.6f + 0.5f * t * t, 0.35f + 2.8f * t, -0.6f + 0.05f * float(i % 3)};
        float size = 0.6f + 1.0f * t;
        std::string name = "smoke " + std::to_string(i);
        b.place(name, b.mesh(makeCard(name, size, size, smoke)), at, facingEye(at));
    }
    // Fire: additive sprites (core) inside partly additive flames.
    for (int i = 0; i < 6; ++i) {
        float t = float(i) / 5.0f;
        glm::vec3 at{2.7f + 0.12f * std::sin(float(i) * 2.1f), 0.6f + 0.9f * t,
                     -0.4f + 0.04f * float(i)};
        std::string name = "fire " + std::to_string(i);
        float size = 0.9f - 0.4f * t;
        b.place(name, b.mesh(makeCard(name, size, size * 1.3f, (i % 2) ? flames : fireCore)), at,
                facingEye(at));
    }

    b.sun({-0.4f, -1.0f, -0.5f}, 2.5f);
    b.pointLight("fire light", {2.7f, 1.1f, -0.2f}, {1.0f, 0.55f, 0.2f}, 8.0f, 8.0f);
    b.camera("main", eye, {0.0f, 1.1f, 0.0f}, 0.8f, 0.1f, 100.0f);
    b.camera("side", {-5.5f, 2.0f, 4.0f}, {0.0f, 1.2f, -0.5f}, 0.8f, 0.1f, 100.0f);
    return scene;
}

// GPU particles (render/particles): rock debris as mesh particles, a lit smoke column
// (alpha-blended sprites with a normal map, lit by the sun, a warm light by the fire and a cool one
// on the left, through the particle lightmap atlas) beside an unlit additive fire, in front of
// opaque geometry. Seeded: every run simulates the same particles.
Scene makeParticles() {
    Scene scene;
    scene.name = "particles";
    SceneBuilder b(scene);
    uint32_t ground = b.material("ground", {0.55f, 0.55f, 0.52f}, 0.9f);
    uint32_t wall = b.material("wall", {0.7f, 0.45f, 0.35f}, 0.8f);
    uint32_t stone = b.material("stone", {0.35f, 0.33f, 0.3f}, 0.9f);
    b.place("ground", b.mesh(makePlane("ground", 30.0f, 30.0f, ground, 4)), {0, 0, 0});
    b.box("back wall", {12.0f, 5.0f, 0.4f}, wall, {0.0f, 0.0f, -3.5f});
    b.box("fire pit", {1.0f, 0.2f, 1.0f}, stone, {1.4f, 0.0f, -0.5f});

    ParticleEmitter smoke;
    smoke.name = "smoke column";
    smoke.position = {-1.2f, 0.2f, -0.6f};
    smoke.spawnRadius = 0.3f;
    smoke.velocity = {0.0f, 0.9f, 0.0f};
    smoke.velocitySpread = 0.2f;
    smoke.acceleration = {0.12f, 0.25f, 0.0f};
    smoke.drag = 0.35f;
    smoke.turbulence = 0.5f;
    smoke.colorStart = {0.6f, 0.6f, 0.62f, 0.75f};
    smoke.colorEnd = {0.45f, 0.45f, 0.48f, 0.55f};
    smoke.sizeStart = 0.6f;
    smoke.sizeEnd = 2.0f;
    smoke.lifetime = 4.0f;
    smoke.particleCount = 96;
    smoke.additiveness = 0.0f;
    smoke.lit = true;
    smoke.wrap = 0.4f;
    smoke.normalScale = 1.0f;
    smoke.seed = 0x5a0ce;
    scene.emitters.push_back(smoke);

    ParticleEmitter fire;
    fire.name = "fire";
    fire.position = {1.4f, 0.25f, -0.5f};
    fire.spawnRadius = 0.25f;
    fire.velocity = {0.0f, 1.2f, 0.0f};
    fire.velocitySpread = 0.25f;
    fire.acceleration = {0.0f, 0.9f, 0.0f};
    fire.drag = 1.2f;
    fire.turbulence = 1.0f;
    fire.colorStart = {3.0f, 1.3f, 0.3f, 0.9f};
    fire.colorEnd = {1.2f, 0.2f, 0.02f, 0.3f};
    fire.sizeStart = 0.7f;
    fire.sizeEnd = 0.25f;
    fire.lifetime = 1.2f;
    fire.particleCount = 64;
    fire.additiveness = 1.0f;
    fire.lit = false;
    fire.seed = 0xf12e;
    scene.emitters.push_back(fire);

    // Mesh particles: embers of rock thrown up from the fire pit, bouncing on the ground; opaque,
    // lit per vertex with wrap shading (the forward path of mesh particles).
    ParticleEmitter debris;
    debris.name = "debris";
    debris.position = {1.4f, 0.3f, -0.5f};
    debris.spawnRadius = 0.3f;
    debris.velocity = {0.0f, 3.2f, 0.4f};
    debris.velocitySpread = 1.2f;
    debris.acceleration = {0.0f, -9.8f, 0.0f};
    debris.drag = 0.1f;
    debris.colorStart = {0.35f, 0.3f, 0.26f, 1.0f};
    debris.colorEnd = {0.2f, 0.18f, 0.16f, 1.0f};
    debris.sizeStart = 0.12f;
    debris.sizeEnd = 0.1f;
    debris.lifetime = 2.5f;
    debris.particleCount = 24;
    debris.lit = true;
    debris.mesh = true;
    debris.vertexLit = true;
    debris.wrap = 0.5f;
    debris.bounce = 0.35f;
    debris.seed = 0xdeb215;
    scene.emitters.push_back(debris);

    b.sun({-0.4f, -1.0f, -0.5f}, 2.0f);
    b.pointLight("fire light", {1.4f, 1.0f, -0.3f}, {1.0f, 0.55f, 0.2f}, 10.0f, 8.0f);
    b.pointLight("cool light", {-3.2f, 2.6f, 1.2f}, {0.35f, 0.5f, 1.0f}, 12.0f, 9.0f);
    b.camera("main", {0.0f, 1.8f, 6.5f}, {0.0f, 1.5f, -0.5f}, 0.8f, 0.1f, 100.0f);
    b.camera("far", {0.0f, 3.0f, 16.0f}, {0.0f, 1.5f, -0.5f}, 0.8f, 0.1f, 100.0f);
    return scene;
}

// The GI test box: a closed room with a red wall (left, -x) and a green wall (right, +x), lit
// only by a shadow-casting spot through an opening in the ceiling, aimed high on the red wall.
// The floor along the red wall lies just outside the spot's cone, so what colours it there is
// the ambient term and whatever the GI carries.
Scene makeCornell() {
    Scene scene;
    scene.name = "cornell";
    scene.skyColor = glm::vec3(0.02f);
    scene.ambientColor = glm::vec3(0.02f);
    scene.environment = Scene::Environment::Hemisphere; // lit as authored, not by a day sky
    SceneBuilder b(scene);
    uint32_t white = b.material("white", {0.8f, 0.8f, 0.8f}, 0.9f);
    uint32_t red = b.material("red", {0.8f, 0.08f, 0.06f}, 0.9f);
    uint32_t green = b.material("green", {0.1f, 0.7f, 0.12f}, 0.9f);
    // Interior: x and z in [-half, half], y in [t, t + height] (the floor slab is y in [0, t]).
    const float half = 2.0f, height = 3.0f, t = 0.1f, hole = 0.7f, top = t + height;
    b.box("floor", {2 * half + 2 * t, t, 2 * half + 2 * t}, white, {0.0f, 0.0f, 0.0f});
    b.box("back wall", {2 * half, height, t}, white, {0.0f, t, -half - t * 0.5f});
    b.box("front wall", {2 * half, height, t}, white, {0.0f, t, half + t * 0.5f});
    b.box("red wall", {t, height, 2 * half + 2 * t}, red, {-half - t * 0.5f, t, 0.0f});
    b.box("green wall", {t, height, 2 * half + 2 * t}, green, {half + t * 0.5f, t, 0.0f});
    // The ceiling: four slabs around a square opening of 2 * hole.
    float side = half + t - hole;
    b.box("ceiling left", {side, t, 2 * half + 2 * t}, white, {-hole - side * 0.5f, top, 0.0f});
    b.box("ceiling right", {side, t, 2 * half + 2 * t}, white, {hole + side * 0.5f, top, 0.0f});
    b.box("ceiling back", {2 * hole, t, side}, white, {0.0f, top, -hole - side * 0.5f});
    b.box("ceiling front", {2 * hole, t, side}, white, {0.0f, top, hole + side * 0.5f});
    b.box("block", {0.8f, 1.2f, 0.8f}, white, {0.8f, t, -0.9f}, 0.3f);
    b.spotLight("spot", {0.0f, top + 0.4f, 0.0f}, {-half, t + 2.1f, 0.0f}, {1.0f, 0.95f, 0.85f},
                40.0f, 12.0f, 0.3f, 0.45f);
    scene.lights.back().castsShadow = true; // a GI light view (reflective shadow map)
    // Every scene has a sun (the renderer's shadow pass expects one); this one is off.
    b.sun({0.3f, -1.0f, 0.2f}, 0.0f);
    b.camera("main", {0.0f, t + 2.3f, half - 0.1f}, {-0.3f, t + 0.4f, -1.2f}, 0.9f, 0.05f, 30.0f);
    // The room's own GI volume (finer than the camera cascades, computed once).
    scene.giVolumes.push_back({"room", Aabb{glm::vec3(-half - t, 0.0f, -half - t),
                                            glm::vec3(half + t, top + t, half + t)}});
    return scene;
}

// Seed 004's arena: a sand floor with a polished stage (smooth enough for screen-space
// reflections), a pool of water, fighters with a skin material, foliage, stands, far buildings
// and open sky. Every surface class of the thin G-buffer (render/screenspace) is on screen.
Scene makeArena() {
    Scene scene;
    scene.name = "arena";
    SceneBuilder b(scene);
    Rng rng(0xA4E4A0004ull);
    uint32_t sand = b.material("sand", {0.76f, 0.66f, 0.48f}, 0.95f);
    uint32_t stage = b.material("polished stage", {0.35f, 0.36f, 0.4f}, 0.08f, 0.0f);
    uint32_t rope = b.material("ring post", {0.85f, 0.1f, 0.08f}, 0.25f, 0.0f);
    uint32_t concrete = b.material("stand concrete", {0.6f, 0.6f, 0.62f}, 0.85f);
    uint32_t far = b.material("far facade", {0.55f, 0.6f, 0.7f}, 0.7f);
    uint32_t water = b.material("water", {0.05f, 0.18f, 0.22f}, 0.04f);
    scene.materials[water].surfaceClass = SurfaceClass::Water;
    uint32_t leaves = b.material("leaves", {0.2f, 0.48f, 0.16f}, 0.75f);
    scene.materials[leaves].surfaceClass = SurfaceClass::Foliage;
    uint32_t skins[3] = {b.material("skin light", {0.92f, 0.7f, 0.58f}, 0.5f),
                         b.material("skin medium", {0.72f, 0.5f, 0.36f}, 0.5f),
                         b.material("skin dark", {0.42f, 0.28f, 0.2f}, 0.5f)};
    for (uint32_t m : skins) scene.materials[m].surfaceClass = SurfaceClass::Skin;
    uint32_t shorts = b.material("shorts", {0.15f, 0.2f, 0.6f}, 0.6f);

    b.place("sand", b.mesh(makePlane("sand", 90.0f, 90.0f, sand, 9)), {0, 0, 0});
    b.box("stage", {12.0f, 0.4f, 12.0f}, stage, {0.0f, 0.0f, 0.0f});
    uint32_t post = b.mesh(makeCylinder("ring post", 0.15f, 1.6f, rope, 16));
    for (int i = 0; i < 4; ++i)
        b.place("ring post " + std::to_string(i), post,
                {i % 2 ? 5.7f : -5.7f, 0.4f, i / 2 ? 5.7f : -5.7f});
    b.place("pool", b.mesh(makePlane("pool", 10.0f, 14.0f, water, 4)), {-13.0f, 0.05f, 2.0f});

    // Fighters: legs, shorts, torso, arms and head; skin everywhere but the shorts.
    const glm::vec3 spots[4] = {
        {-1.6f, 0.4f, 0.6f}, {1.5f, 0.4f, -0.4f}, {0.2f, 0.4f, 2.6f}, {-3.0f, 0.0f, 7.5f}};
    for (int i = 0; i < 4; ++i) {
        uint32_t skin = skins[i % 3];
        std::string n = "fighter " + std::to_string(i);
        glm::vec3 at = spots[i];
        float yaw = rng.uniform(0.0f, 6.28f);
        uint32_t leg = b.mesh(makeCylinder(n + " leg", 0.13f, 0.85f, skin, 16));
        b.place(n + " left leg", leg, at + glm::vec3(-0.16f, 0.0f, 0.0f), yaw);
        b.place(n + " right leg", leg, at + glm::vec3(0.16f, 0.0f, 0.0f), yaw);
        b.place(n + " shorts", b.mesh(makeCylinder(n + " shorts", 0.33f, 0.3f, shorts, 20)),
                at + glm::vec3(0, 0.8f, 0), yaw);
        b.place(n + " torso", b.mesh(makeCylinder(n + " torso", 0.3f, 0.65f, skin, 20)),
                at + glm::vec3(0, 1.1f, 0), yaw);
        uint32_t arm = b.mesh(makeCylinder(n + " arm", 0.09f, 0.7f, skin, 12));
        b.place(n + " left arm", arm, at + glm::vec3(-0.42f, 1.05f, 0.0f), yaw);
        b.place(n + " right arm", arm, at + glm::vec3(0.42f, 1.05f, 0.0f), yaw);
        b.place(n + " head", b.mesh(makeSphere(n + " head", 0.2f, skin, 24, 12)),
                at + glm::vec3(0, 1.97f, 0));
    }
    for (Instance& inst : scene.instances) inst.character = inst.name.rfind("fighter", 0) == 0;
    // Foliage around the arena, stands behind it, buildings far beyond.
    uint32_t bush = b.mesh(makeSphere("bush", 1.2f, leaves, 20, 10));
    for (int i = 0; i < 12; ++i) {
        float a = float(i) / 12.0f * 6.2832f;
        b.place("bush " + std::to_string(i), bush,
                {std::cos(a) * 20.0f, 1.2f, std::sin(a) * 20.0f - 4.0f});
    }
    for (int i = 0; i < 3; ++i)
        b.box("stand " + std::to_string(i), {14.0f, 2.0f + 2.0f * float(i), 3.0f}, concrete,
              {0.0f, 0.0f, -12.0f - 3.0f * float(i)});
    for (int i = 0; i < 8; ++i) {
        float x = -140.0f + 40.0f * float(i);
        b.box("far building " + std::to_string(i), {18.0f, rng.uniform(20.0f, 60.0f), 18.0f}, far,
              {x, 0.0f, -160.0f});
    }
    b.sun({-0.4f, -1.0f, -0.5f}, 3.0f);
    b.pointLight("ring light", {0.0f, 5.0f, 3.0f}, {1.0f, 0.9f, 0.8f}, 40.0f, 14.0f);
    b.camera("main", {4.0f, 2.6f, 11.0f}, {-2.0f, 2.0f, -10.0f}, 0.9f, 0.1f, 400.0f);
    b.camera("fighters", {1.0f, 1.9f, 5.0f}, {-0.4f, 1.3f, 0.0f}, 0.7f, 0.1f, 400.0f);
    return scene;
}

const std::vector<std::pair<std::string, std::function<Scene()>>>& registry() {
    static const std::vector<std::pair<std::string, std::function<Scene()>>> scenes = {
        {"default", makeDefault},
        {"checker", makeChecker},
        {"smooth", makeSmooth},
        {"many", [] { return makeMany(kManyDefaultInstances); }},
        {"transparency", makeTransparency},
        {"particles", makeParticles},
        {"lights", [] { return makeLightsScene(makeDefault()); }},
        {"blockers", makeBlockersScene},
        {"textured-lights", makeTexturedLightsScene},
        {"cornell", makeCornell},
        {"arena", makeArena},
        {"decals", makeDecalsScene},
        {"textures", [] { return makeTextureGallery(); }},
        {"materials", makeMaterialsScene},
    };
    return scenes;
}

} // namespace

std::vector<std::string> builtinSceneNames() {
    std::vector<std::string> names;
    for (const auto& [name, make] : registry()) names.push_back(name);
    return names;
}

Scene makeBuiltinScene(const std::string& name, const BuiltinSceneOptions& options) {
    if (options.instances != 0 && name != "many")
        throw InputError(format("--instances %u: only builtin:many takes an instance count (scene "
                                "builtin:%s)",
                                options.instances, name.c_str()));
    if (name == "many" && options.instances != 0) {
        if (options.instances > kManyMaxInstances)
            throw InputError(
                format("--instances %u: expected 1..%u", options.instances, kManyMaxInstances));
        return makeMany(options.instances);
    }
    if (options.galleryTextureSize != 0 && name != "textures")
        throw InputError(format("--gallery-texture-size %u: only builtin:textures takes a texture "
                                "size (scene builtin:%s)",
                                options.galleryTextureSize, name.c_str()));
    if (name == "textures") return makeTextureGallery(options.galleryTextureSize);
    for (const auto& [known, make] : registry())
        if (known == name) return make();
    std::string list;
    for (const auto& [known, make] : registry()) list += (list.empty() ? "" : ", ") + known;
    throw InputError("builtin:" + name + ": unknown built-in scene (known: " + list + ")");
}

} // namespace shadel
