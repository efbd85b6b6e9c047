#pragma once
// The thin G-buffer: what the screen-space passes read of the visible surface, drawn
// by a raster pass over the prepass depth (equal test, no depth writes) from the same camera
// lists: world normal + roughness (RGBA16F) and one byte of PIXEL_* flags with the surface class
// (shaders/screenspace/gbuffer.frag). The decoupled path could fill it from its reconstruction.
#include "rhi/handles.h"
#include "rhi/pipeline.h"

namespace shadel {

struct Renderer;

struct ThinGBuffer {
    TextureHandle normalRoughness, flags;
    RenderTargetView normalTarget, flagsTarget;
    TextureReadView normalRead, flagsRead;
    Pipeline pipeline;
};

ThinGBuffer createThinGBuffer(Renderer& r);
void destroyThinGBuffer(Renderer& r, ThinGBuffer& g);
// Draws the camera lists into the G-buffer; leaves it readable by compute shaders.
void recordThinGBuffer(Renderer& r, ThinGBuffer& g, VkCommandBuffer cmd, uint64_t frame);

} // namespace shadel
