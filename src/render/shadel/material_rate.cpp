#include "render/shadel/material_rate.h"

#include <algorithm>
#include <cmath>
#include <optional>

namespace shadel {

// shadelLevels (shaders/shadel/shadel.glsl) narrows the MIP blend band by the bias as a fraction
// of one MIP (band x (1 - rateBias)): a larger cap would need that fraction passed to the GPU.
static_assert(MaterialRate{}.maxBias == 1.0f, "shadelLevels takes the full bias as 1 MIP");

float materialRateBias(const MaterialRate& rate, uint32_t features, float roughness) {
    if ((features & ~MATERIAL_FEATURE_TEXTURES) != 0u || !std::isfinite(roughness)) return 0.0f;
    float span = rate.broadRoughness - rate.sharpRoughness;
    float t = span > 0.0f ? (roughness - rate.sharpRoughness) / span
                          : (roughness >= rate.broadRoughness ? 1.0f : 0.0f);
    return rate.maxBias * std::clamp(t, 0.0f, 1.0f);
}

float materialRateLod(float lod, float rateBias, float textureLod) {
    float bias = std::min(rateBias, std::max(textureLod - 1.0f - lod, 0.0f));
    return std::max(lod, std::min(lod + bias, float(SHADEL_MATERIAL_RATE_MAX_LOD)));
}

bool lightDrawsSharpEdges(const gpu::GpuLight& light) {
    // Round spots, omnis, tubes and darks fall off smoothly (builtin:lights' round spots blend
    // over 0.05-0.3 rad); the sun's edges are its shadow map's (see the header).
    if (light.type == LIGHT_DIRECTIONAL) return false;
    return light.type == LIGHT_SPOT_SQUARE || light.type == LIGHT_AREA ||
           (light.flags & (LIGHT_FLAG_PROJECTED | LIGHT_FLAG_CLIP_PLANE)) != 0u ||
           light.blockerCount > 0u || light.shadowIndex != LIGHT_NO_SHADOW;
}

void updateSharpLights(SharpLights& sharp, const std::vector<gpu::GpuLight>& lights,
                       bool lightsChanged, bool sunDrawsSharpEdges,
                       const std::vector<Decal>& decals) {
    if (sharp.version != 0 && !lightsChanged && sharp.sunSharp == sunDrawsSharpEdges)
        return; // (the decals are the scene's: they do not change)
    sharp.sunSharp = sunDrawsSharpEdges;
    sharp.spheres.clear();
    sharp.anyInfinite = sunDrawsSharpEdges;
    sharp.decalBoxes.clear();
    for (const Decal& decal : decals) { // the box's world bounds
        glm::vec3 axisY = glm::cross(decal.axisZ, decal.axisX);
        glm::vec3 half =
            0.5f * (glm::abs(decal.axisX) * decal.size.x + glm::abs(axisY) * decal.size.y +
                    glm::abs(decal.axisZ) * decal.size.z);
        sharp.decalBoxes.push_back(decal.center - half);
        sharp.decalBoxes.push_back(decal.center + half);
    }
    std::vector<gpu::GpuLight> sharpLights;
    for (const gpu::GpuLight& light : lights) {
        if (!lightDrawsSharpEdges(light)) continue;
        glm::vec4 sphere = lightBoundingSphere(light);
        if (!(sphere.w >= 0.0f) || !std::isfinite(sphere.w)) {
            sharp.anyInfinite = true;
            continue;
        }
        sharp.spheres.push_back(sphere);
        sharpLights.push_back(light);
    }
    sharp.grid = buildLightGrid(sharpLights); // indices into spheres, as sharpLights
    sharp.version++;
}

static bool sphereMeetsBox(glm::vec4 s, glm::vec3 lo, glm::vec3 hi) {
    glm::vec3 c(s);
    glm::vec3 d = c - glm::clamp(c, lo, hi);
    return glm::dot(d, d) <= s.w * s.w;
}

bool sharpLightReaches(const SharpLights& sharp, glm::vec3 boxMin, glm::vec3 boxMax) {
    if (sharp.anyInfinite) return true;
    for (size_t i = 0; i + 1 < sharp.decalBoxes.size(); i += 2)
        if (glm::all(glm::lessThanEqual(sharp.decalBoxes[i], boxMax)) &&
            glm::all(glm::lessThanEqual(boxMin, sharp.decalBoxes[i + 1])))
            return true;
    if (sharp.spheres.empty()) return false;
    std::optional<std::vector<uint32_t>> candidates =
        lightGridCandidates(sharp.grid, boxMin, boxMax);
    if (!candidates) { // a box larger than the grid's cells: every sharp light
        for (const glm::vec4& s : sharp.spheres)
            if (sphereMeetsBox(s, boxMin, boxMax)) return true;
        return false;
    }
    for (uint32_t i : *candidates)
        if (i < sharp.spheres.size() && sphereMeetsBox(sharp.spheres[i], boxMin, boxMax))
            return true;
    return false;
}

} // namespace shadel
