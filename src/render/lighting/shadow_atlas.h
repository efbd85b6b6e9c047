#pragma once
// A depth atlas of shadow maps, shared by the sun's cascades and the shadow-casting spots: the
// texture, its attachment and sampled views, and the depth-only pipeline (depth clamp, slope
// bias) that draws casters into it. A frame's maps are drawn between beginShadowAtlas and
// endShadowAtlas, one viewport per map; shading then samples `read`
// (shaders/lighting/shadows.glsl).
#include "rhi/handles.h"
#include "rhi/pipeline.h"
#include "rhi/vk.h"

namespace shadel {

struct Gpu;

struct ShadowAtlas {
    TextureHandle texture;
    DepthTargetView target;
    TextureReadView read;
    Pipeline pass;
    uint32_t width = 0, height = 0;
};

// `name` names the texture ("<name>Atlas") and the pipeline; throws DeviceError when out of memory.
// `alphaMasked`: the scene has alpha-masked materials, whose casters the fragment shader tests;
// without them the pass is depth-only.
ShadowAtlas createShadowAtlas(Gpu& gpu, const char* name, uint32_t width, uint32_t height,
                              const char* vertexShader, bool alphaMasked);
void destroyShadowAtlas(Gpu& gpu, ShadowAtlas& atlas);

// Clears the atlas and binds its pipeline, depth bias and the scene's index buffer; the viewport
// covers the whole atlas (one map) until setShadowMapViewport picks a map.
void beginShadowAtlas(Gpu& gpu, VkCommandBuffer cmd, const ShadowAtlas& atlas,
                      VkBuffer sceneIndices);
// The viewport and scissor of one square map at texel (x, y).
void setShadowMapViewport(VkCommandBuffer cmd, uint32_t x, uint32_t y, uint32_t size);
// Ends the pass; the atlas is left for sampling by fragment and compute shading.
void endShadowAtlas(Gpu& gpu, VkCommandBuffer cmd, const ShadowAtlas& atlas);

} // namespace shadel
