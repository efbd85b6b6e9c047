#include "scene/builtin_gallery.h"

#include <algorithm>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"
#include "core/log.h"
#include "scene/procedural_textures.h"

namespace shadel {

// One panel: a kPanel x kPanel m quad centred at the origin in the XY plane facing +Z, uv (0,0)
// at its top left (the whole texture once).
// Panels nearly fill the walls of a narrow corridor: the nearest ones want their textures at
// full resolution at 1280x720 (about 1500 texels across from 1.6 m), the far end only tails.
constexpr float kPanel = 2.4f;

static Mesh panelMesh(uint32_t material) {
    Mesh m;
    m.name = "panel";
    m.material = material;
    const glm::vec3 n{0, 0, 1};
    const glm::vec4 t{1, 0, 0, 1};
    const float h = 0.5f * kPanel;
    m.vertices = {{{-h, h, 0}, n, t, {0, 0}},
                  {{h, h, 0}, n, t, {1, 0}},
                  {{h, -h, 0}, n, t, {1, 1}},
                  {{-h, -h, 0}, n, t, {0, 1}}};
    m.indices = {0, 3, 2, 0, 2, 1};
    for (const Vertex& v : m.vertices) m.bounds.extend(v.position);
    return m;
}

static Mesh floorMesh(uint32_t material, float sizeX, float sizeZ, glm::vec3 centre) {
    Mesh m;
    m.name = "floor";
    m.material = material;
    const glm::vec3 n{0, 1, 0};
    const glm::vec4 t{1, 0, 0, 1};
    float hx = sizeX * 0.5f, hz = sizeZ * 0.5f;
    m.vertices = {{centre + glm::vec3(-hx, 0, -hz), n, t, {-hx, -hz}},
                  {centre + glm::vec3(hx, 0, -hz), n, t, {hx, -hz}},
                  {centre + glm::vec3(hx, 0, hz), n, t, {hx, hz}},
                  {centre + glm::vec3(-hx, 0, hz), n, t, {-hx, hz}}};
    m.indices = {0, 3, 2, 0, 2, 1};
    for (const Vertex& v : m.vertices) m.bounds.extend(v.position);
    return m;
}

Scene makeTextureGallery(uint32_t textureSize) {
    if (textureSize == 0) textureSize = kGalleryFullTextureSize;
    if (textureSize < 16 || textureSize > 8192 || (textureSize & (textureSize - 1)) != 0)
        throw InputError(
            format("--gallery-texture-size %u: expected a power of two in 16..8192", textureSize));
    Scene scene;
    scene.name = "textures";
    scene.skyColor = {0.35f, 0.4f, 0.5f};
    scene.ambientColor = {0.25f, 0.25f, 0.27f};
    scene.environment = Scene::Environment::Hemisphere; // lit as authored, not by a day sky
    const float spacing = 2.5f, wallX = 1.6f;
    const uint32_t perWall = kGalleryPanels / 2;
    Material floorMat;
    floorMat.name = "floor";
    floorMat.baseColorFactor = {0.5f, 0.48f, 0.45f, 1.0f};
    floorMat.roughnessFactor = 0.9f;
    floorMat.procedural = Procedural::Bricks;
    floorMat.proceduralScale = 1.0f;
    scene.materials.push_back(floorMat);
    float length = spacing * float(perWall) + 4.0f;
    scene.meshes.push_back(
        floorMesh(0, 2.0f * wallX + 2.0f, length, {0.0f, 0.0f, 2.0f - 0.5f * length}));
    scene.instances.push_back({"floor", 0, glm::mat4(1.0f)});
    for (uint32_t i = 0; i < kGalleryPanels; ++i) {
        Texture tex;
        tex.name = "gallery" + std::to_string(i);
        tex.width = tex.height = textureSize;
        tex.srgb = true;
        tex.procedural = {1 + i % kProceduralTextureKinds, i};
        scene.textures.push_back(std::move(tex));
        // Unlit: the panel shows its texture as stored, so the image measures the texture
        // streaming alone (no lighting to hide a coarse level).
        Material m;
        m.name = "panel" + std::to_string(i);
        m.baseColorFactor = glm::vec4(1.0f);
        m.baseColorTexture = int32_t(i);
        m.unlit = true;
        m.doubleSided = true;
        scene.materials.push_back(m);
        scene.meshes.push_back(panelMesh(uint32_t(scene.materials.size() - 1)));
        bool left = i % 2 == 0;
        float z = -spacing * float(i / 2);
        // Left wall faces +X, right wall -X.
        glm::mat4 place = glm::translate(glm::mat4(1.0f), {left ? -wallX : wallX, 1.5f, z});
        place = glm::rotate(place, glm::radians(left ? 90.0f : -90.0f), glm::vec3(0, 1, 0));
        scene.instances.push_back(
            {"panel" + std::to_string(i), uint32_t(scene.meshes.size() - 1), place});
    }
    Light sun;
    sun.name = "sun";
    sun.type = LightType::Directional;
    sun.direction = glm::normalize(glm::vec3(0.2f, -1.0f, -0.3f));
    sun.intensity = 2.0f;
    sun.castsShadow = true;
    scene.lights.push_back(sun);
    auto camera = [&](const char* name, glm::vec3 position, glm::vec3 target) {
        Camera c;
        c.name = name;
        c.position = position;
        c.forward = glm::normalize(target - position);
        c.up = glm::normalize(glm::vec3(0, 1, 0) - c.forward * c.forward.y);
        c.yfov = 0.8f;
        c.znear = 0.1f;
        c.zfar = 200.0f;
        scene.cameras.push_back(c);
    };
    // Down the corridor (the walk goes along it), and a cut to its far end looking back.
    camera("main", {0.0f, 1.6f, 3.0f}, {-0.8f, 1.5f, -20.0f});
    camera("back", {0.0f, 1.6f, -spacing * float(perWall)}, {0.8f, 1.5f, -30.0f});
    return scene;
}

} // namespace shadel
