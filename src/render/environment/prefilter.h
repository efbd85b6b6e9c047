#pragma once
// Prefiltered environment maps for image-based lighting, computed on the CPU.
//
// Specular: an equirectangular MIP chain whose level l holds the radiance convolved with the GGX
// lobe of perceptual roughness l / (levels - 1) (normal = view = reflection direction, weighted
// by n.l), level 0 the source itself. Importance sampled with the same Hammersley set in every
// texel; each sample reads the source's MIP pyramid at the level whose texels match the sample's
// share of the lobe, so low sample counts neither alias nor miss small bright sources.
// Diffuse: irradiance / pi (the Lambert radiance of albedo 1), summed over every texel of a
// 128x64 level of the source. BRDF table: the split-sum scale and bias of the glTF BRDF's
// specular (GGX, height-correlated Smith) and the Charlie sheen's directional albedo.
#include <cstdint>
#include <functional>
#include <vector>

#include "render/environment/equirect.h"

namespace shadel {

class WorkerPool;

struct PrefilterSettings {
    uint32_t specularWidth = 512; // level 0; height = width / 2, each level half the last
    uint32_t sheenWidth = 128;    // level 0 of the sheen chain (sheenLevels levels)
    // Perceptual roughness of level l = l / (levels - 1). Five levels keep the roughest (the
    // widest lobe) at 32x16 texels, enough for the shading across a rough sphere that a 4x2 level
    // flattens, at a step of 0.25 in roughness, as the glTF reference renderer's chain has.
    uint32_t specularLevels = 5;
    uint32_t specularSamples = 256; // per texel and level
    uint32_t irradianceWidth = 64;  // height = width / 2
    uint32_t brdfSize = 64;         // the BRDF table is brdfSize x brdfSize
    uint32_t sheenLevels = 7;       // sheen roughness of level l = max(l / (levels - 1), min)
};

// Reports the share of the work done, 0..1, from the calling thread only.
using PrefilterProgress = std::function<void(float)>;

std::vector<EquirectImage> prefilterSpecular(const EquirectImage& source,
                                             const PrefilterSettings& settings, WorkerPool& pool,
                                             const PrefilterProgress& progress = {});
// The smallest sheen roughness the shaders use (shaders/common/material.glsl clamps to it).
constexpr float kMinSheenRoughness = 0.07f;

// The same chain for the sheen lobe: level l convolved with the Charlie distribution of sheen
// roughness max(l / (levels - 1), kMinSheenRoughness), weighted by n.l, over the part of the
// lobe above the horizon (with n = v, half vectors within 45 degrees of n).
// Levels of the sheen chain: as many as the specular chain, but none narrower than 2x1 (the
// image's own MIP chain).
uint32_t sheenLevelCount(const PrefilterSettings& settings);
std::vector<EquirectImage> prefilterSheen(const EquirectImage& source,
                                          const PrefilterSettings& settings, WorkerPool& pool,
                                          const PrefilterProgress& progress = {});

enum class PrefilterLobe { Ggx, Charlie };
// Either chain: `levels` levels from `width` x width / 2 down, `samples` per texel.
std::vector<EquirectImage> prefilterLobes(const EquirectImage& source, PrefilterLobe lobe,
                                          uint32_t width, uint32_t levels, uint32_t samples,
                                          WorkerPool& pool, const PrefilterProgress& progress = {});

EquirectImage prefilterIrradiance(const EquirectImage& source, uint32_t width, WorkerPool& pool);

// texel (x, y): n.v = (x + 0.5) / size, perceptual roughness = (y + 0.5) / size; R = scale and
// G = bias of F0 in the split-sum specular (E = F0 * R + F90 * G), B = the sheen's directional
// albedo for sheen roughness y (Charlie distribution, shadel's sheen visibility).
struct BrdfTable {
    uint32_t size = 0;
    std::vector<glm::vec3> texels;
};
BrdfTable integrateBrdf(uint32_t size, WorkerPool& pool);

} // namespace shadel
