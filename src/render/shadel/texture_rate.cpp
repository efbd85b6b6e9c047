#include "render/shadel/texture_rate.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "render/gpu_scene.h"
#include "scene/scene.h"

namespace shadel {

namespace {

// The value below which `fraction` of the total weight lies.
float weightedPercentile(std::vector<std::pair<float, double>>& valueWeight, double fraction) {
    std::sort(valueWeight.begin(), valueWeight.end());
    double total = 0.0;
    for (const auto& [value, weight] : valueWeight) total += weight;
    double target = fraction * total, sum = 0.0;
    for (const auto& [value, weight] : valueWeight) {
        sum += weight;
        if (sum >= target) return value;
    }
    return valueWeight.back().first;
}

double triangleArea(glm::vec2 a, glm::vec2 b, glm::vec2 c) {
    glm::dvec2 u = glm::dvec2(b) - glm::dvec2(a), v = glm::dvec2(c) - glm::dvec2(a);
    return 0.5 * std::abs(u.x * v.y - u.y * v.x);
}

// The 2nd percentile of a metallic-roughness texture's G (roughness), 0..1; -1 when its texels
// are not in the scene (generated later: procedural).
float lowRoughness(const Texture& t) {
    size_t texels = size_t(t.width) * t.height;
    if (t.rgba8.size() != texels * 4 || texels == 0) return -1.0f;
    uint64_t histogram[256] = {};
    for (size_t i = 0; i < texels; ++i) histogram[t.rgba8[i * 4 + 1]]++;
    uint64_t low = texels / 50, sum = 0;
    uint32_t g = 0;
    for (; g < 255; ++g)
        if ((sum += histogram[g]) > low) break;
    return float(g) / 255.0f;
}

} // namespace

float uvPerShadelLog2(std::span<const glm::vec2> materialUv, std::span<const glm::vec2> shadelUv,
                      std::span<const uint32_t> indices, glm::uvec2 mip0Size) {
    const float none = -std::numeric_limits<float>::infinity();
    double shadelScale = double(mip0Size.x) * double(mip0Size.y);
    if (shadelScale <= 0.0 || materialUv.size() != shadelUv.size()) return none;
    // Per triangle: log2 of UV units per shadel (linear), weighted by its shadel area.
    std::vector<std::pair<float, double>> density;
    density.reserve(indices.size() / 3);
    for (size_t t = 0; t + 2 < indices.size(); t += 3) {
        uint32_t i0 = indices[t], i1 = indices[t + 1], i2 = indices[t + 2];
        if (i0 >= shadelUv.size() || i1 >= shadelUv.size() || i2 >= shadelUv.size()) continue;
        double shadels = triangleArea(shadelUv[i0], shadelUv[i1], shadelUv[i2]) * shadelScale;
        double uv = triangleArea(materialUv[i0], materialUv[i1], materialUv[i2]);
        if (!(shadels > 1e-12) || !std::isfinite(uv)) continue; // degenerate: no surface
        // A triangle whose UVs collapse (a constant lookup) has no texture detail.
        density.push_back({uv > 0.0 ? float(0.5 * std::log2(uv / shadels)) : none, shadels});
    }
    if (density.empty()) return none;
    return weightedPercentile(density, 0.95);
}

std::vector<MaterialTexels> materialTexels(const Scene& scene) {
    std::vector<MaterialTexels> out(scene.materials.size());
    // Per texture, once: materials often share one (linear in the scene's texels).
    std::vector<float> roughnessOfTexture(scene.textures.size(),
                                          std::numeric_limits<float>::quiet_NaN());
    for (size_t mi = 0; mi < scene.materials.size(); ++mi) {
        const Material& m = scene.materials[mi];
        MaterialTexels& e = out[mi];
        e.known = true;
        e.texelsPerUvLog2 = -std::numeric_limits<float>::infinity();
        e.texelsPerUv1Log2 = -std::numeric_limits<float>::infinity();
        // The slots a textured material without extension features samples (the clear coat and
        // sheen slots come with features of their own, which keep the full rate).
        const int32_t slots[] = {m.baseColorTexture,    m.metallicRoughnessTexture,
                                 m.normalTexture,       m.emissiveTexture,
                                 m.occlusionTexture,    m.specularTexture,
                                 m.specularColorTexture};
        const TextureSlot slotOf[] = {TextureSlot::BaseColor,    TextureSlot::MetallicRoughness,
                                      TextureSlot::Normal,       TextureSlot::Emissive,
                                      TextureSlot::Occlusion,    TextureSlot::Specular,
                                      TextureSlot::SpecularColor};
        for (size_t k = 0; k < std::size(slots); ++k) {
            if (slots[k] == kNoTexture) continue;
            if (slots[k] < 0 || size_t(slots[k]) >= scene.textures.size()) {
                e.known = false;
                continue;
            }
            const Texture& t = scene.textures[size_t(slots[k])];
            const UvTransform& x = m.uvTransforms[uint32_t(slotOf[k])];
            // KHR_texture_transform scales UVs: texels per UV unit grow with |det|.
            double det = std::abs(double(x.c0.x) * x.c1.y - double(x.c0.y) * x.c1.x);
            double texels = double(t.width) * double(t.height) * det;
            if (!(texels > 0.0) || !std::isfinite(texels)) continue; // a constant lookup
            float& densest =
                m.texCoords[uint32_t(slotOf[k])] == 1 ? e.texelsPerUv1Log2 : e.texelsPerUvLog2;
            densest = std::max(densest, float(0.5 * std::log2(texels)));
        }
        if (m.metallicRoughnessTexture != kNoTexture && e.known) {
            float& scale = roughnessOfTexture[size_t(m.metallicRoughnessTexture)];
            if (std::isnan(scale))
                scale = lowRoughness(scene.textures[size_t(m.metallicRoughnessTexture)]);
            if (scale < 0.0f)
                e.known = false; // generated later (procedural): not known
            else
                e.roughnessScale = scale;
        }
    }
    return out;
}

bool sameTextures(const gpu::GpuMaterial& a, const gpu::GpuMaterial& b) {
    return materialTextureSlots(a) == materialTextureSlots(b) &&
           std::memcmp(a.samplers, b.samplers, sizeof(a.samplers)) == 0 &&
           std::memcmp(a.uvTransform, b.uvTransform, sizeof(a.uvTransform)) == 0 &&
           a.texCoords == b.texCoords;
}

float textureLod(float uvPerShadelLog2, float texelsPerUvLog2, float shadelsPerTexel) {
    // (Both terms are finite or -infinity: no texture detail gives +infinity, clamped to NONE.)
    float lod = std::floor(-(uvPerShadelLog2 + texelsPerUvLog2) - std::log2(shadelsPerTexel));
    return std::clamp(lod, -float(SHADEL_TEXTURE_LOD_NONE), float(SHADEL_TEXTURE_LOD_NONE));
}

} // namespace shadel
