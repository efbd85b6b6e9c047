#pragma once
// Material shading rate (--material-rate on|off): decoupled shading chooses how densely an object
// is shaded independently of the pixels, so it can shade each object no finer than its content
// needs. A material with no pattern of its own (no texture, procedural, clear coat or sheen: the
// plain shading class) shows only lighting on its surface, and lighting is smooth across a
// surface except where a glossy lobe makes sharp highlights or a light draws sharp edges. Such a
// material is shaded up to one MIP coarser (GpuShadelObject::rateBias, added to the sample's LOD
// by shadelLevels in shaders/shadel/shadel.glsl, so marking, reconstruction and the debug views
// agree) the broader its specular lobe is: none at roughness <= sharpRoughness, a full MIP at
// >= broadRoughness, and never past LOD SHADEL_MATERIAL_RATE_MAX_LOD (where chart gutters bleed:
// shared_types.h). It keeps the full rate where a light with sharp edges reaches it (square
// spots, gobos, textured area lights, clip planes, blockers, shadow-mapped spots:
// lightDrawsSharpEdges), where a decal's box meets it (decals draw patterns on the surface),
// and, everywhere, when the sun draws sharp edges: ray-traced terms (hard traced shadows, AO,
// GI: the RT cache sets its own rate, --rt-shadel-mip-offset) or sun cascades (near shadow
// texels about a pixel wide). Materials with procedurals, clear coat or sheen keep it too: their
// pattern is the signal. A textured material takes the same bias where the view magnifies its
// textures, never coarser than a quarter texel (texture_rate.h). The sun's one whole-scene shadow
// map is not counted: its PCF edges are wider than a shadel of the coarser level in the scenes
// measured (builtin:default).
#include <cstdint>
#include <vector>

#include "common/shared_types.h"
#include "render/lighting/light_grid.h"
#include "scene/decal.h"

namespace shadel {

struct MaterialRate {
    float maxBias = 1.0f;         // MIPs coarser at most (a quarter of the shadels)
    float sharpRoughness = 0.25f; // at or below: highlights sharp enough to keep the full rate
    float broadRoughness = 0.55f; // at or above: the full bias
    // Textured materials: textureLod is the finest whole level whose shadels are at most
    // 1 / shadelsPerTexel texel apart; the rate stops a level finer (texture_rate.h).
    float shadelsPerTexel = 2.0f;
};

// The MIP bias for a material with `features` (MATERIAL_FEATURE_* of shared_types.h) and
// roughness `roughness` (of a textured material: the lowest its roughness texture gives,
// texture_rate.h). 0 when any feature but textures is set; a textured material's bias is then
// limited per sample by its texels (textureLod).
float materialRateBias(const MaterialRate& rate, uint32_t features, float roughness);

// A sample's LOD with an object's rate bias, as shadelLevels (shaders/shadel/shadel.glsl) takes
// it: coarser by the bias, but not past SHADEL_MATERIAL_RATE_MAX_LOD (shared_types.h) unless
// already there, nor past the level before `textureLod` (texture_rate.h: a quarter texel of a
// textured material's densest texture) unless already there.
float materialRateLod(float lod, float rateBias, float textureLod = SHADEL_TEXTURE_LOD_NONE);

// Whether a light draws edges sharper than its smooth falloff on what it lights.
bool lightDrawsSharpEdges(const gpu::GpuLight& light);

// The frame's lights that draw sharp edges, bucketed in world space (render/lighting/light_grid.h)
// so an object's box finds the few near it. Rebuilt only when the lights change; `version`
// counts the rebuilds, so a per-object answer can be kept until it changes.
struct SharpLights {
    bool sunSharp = false;
    std::vector<glm::vec3> decalBoxes; // world bounds of the decals' boxes: min, max pairs
    std::vector<glm::vec4> spheres;    // of the sharp lights (lightBoundingSphere; w < 0: infinite)
    bool anyInfinite = false;
    LightGridData grid;
    uint32_t version = 0;
};

// lightsChanged: any light differs from last frame's (Renderer::changedLightVolumes not
// empty); the first call always builds.
void updateSharpLights(SharpLights& sharp, const std::vector<gpu::GpuLight>& lights,
                       bool lightsChanged, bool sunDrawsSharpEdges,
                       const std::vector<Decal>& decals);

// Whether any sharp light's bounding sphere or any decal's box meets the box.
bool sharpLightReaches(const SharpLights& sharp, glm::vec3 boxMin, glm::vec3 boxMax);

} // namespace shadel
