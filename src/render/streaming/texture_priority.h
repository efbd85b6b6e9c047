#pragma once
// Texture streaming priorities: the CPU's from texel density and the projected size of
// the instances using a texture, the GPU's from what shading sampled (shaders/streaming/
// feedback.glsl), merged into one "wanted side in texels" per texture.
#include <cstdint>
#include <vector>

#include "render/camera.h"
#include "scene/scene.h"

namespace shadel {

// One instance's use of a texture: its world bounding sphere and how many material UV units a
// metre of its surface spans (texel density = texture side x uvPerMetre texels per metre).
struct TextureUse {
    uint32_t texture = 0;
    glm::vec3 center{0.0f};
    float radius = 0.0f;
    float uvPerMetre = 1.0f;
};

std::vector<TextureUse> textureUses(const Scene& scene);

// The side each texture needs so one texel covers at most one pixel at the nearest point of each
// instance using it (conservative: "CPU often overshoots"); instances outside the view count a
// quarter (prefetch, below what is seen). viewportHeight in pixels.
std::vector<float> cpuWantedSizes(const std::vector<TextureUse>& uses, size_t textureCount,
                                  const CameraView& camera, float viewportHeight);

// The split: the CPU's estimate is trusted for the small and middle layers (up to cpuCap), where
// being early matters most and its overshoot costs little; above, only the GPU's exact, latent wish
// counts. gpuWanted = 0 when shading has not sampled the texture lately.
float mergedWanted(float cpuWanted, float gpuWanted, float cpuCap);

} // namespace shadel
