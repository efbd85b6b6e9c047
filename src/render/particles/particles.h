#pragma once
// GPU particles: emitters simulated in compute, drawn as camera-plane sprites into
// the WBOIT targets of render/oit (no sorting; additiveness per emitter: fire adds, smoke
// blends), lit per pixel, per vertex, or through the particle lightmap atlas: every frame each
// visible lit sprite gets a rectangle at an LOD from its estimated screen size (repacked from
// scratch by a GPU shelf packer, shaders/particles/particle_atlas.h), a compute pass lights
// every texel from the sprite's position and normal map with the full light list, and the
// sprites read their lighting from it (--particle-lighting atlas|pixel|vertex).
//
// Deterministic: births and motion are seeded by emitter, particle index and generation, and
// the simulation advances a fixed step (1/60 s) per frame, after a prewarm on the first frame
// that fills the emitters, so frame N of a run is the same in every run.
#include <array>
#include <cstdint>

#include <nlohmann/json.hpp>

#include "particles/particle_atlas.h"
#include "render/renderer.h"
#include "rhi/frame.h"

namespace shadel {

struct GpuScene;

// Null when the scene has no emitter or RenderSettings::particles is off.
ParticleStatePtr createParticles(Renderer& r, const GpuScene& scene);
void destroyParticles(Renderer& r, ParticleStatePtr& state);

// CPU: this frame's simulation step count and time, atlas slots (renderFrame's frontend).
void prepareParticleFrame(Renderer& r);
// `particleSimulate` then, with --particle-lighting atlas, `particleAtlasLighting`.
void recordParticlePasses(Renderer& r, FrameRecorder& rec, uint64_t frame);
// `particleSprites`: into the WBOIT targets, between their accumulation and composite
// (render/oit records it).
bool particlesThisFrame(const Renderer& r);
// With --particle-resolution half (the default) `particleSpritesHalf` draws them into their own
// half-resolution WBOIT targets instead; the composite (render/oit) reads those through
// particleHalfResTargets and combines both accumulations before resolving.
void recordParticleSprites(Renderer& r, FrameRecorder& rec, uint64_t frame);
bool particleHalfResTargets(const Renderer& r, uint32_t& accumSlot, uint32_t& revealSlot);
// --visualize particle-atlas: `particleAtlasView` draws the atlas over the scene colour.
void recordParticleAtlasView(Renderer& r, FrameRecorder& rec, uint64_t frame);

// Read back after the frame (stats: "particles").
struct ParticleStats {
    uint32_t particles = 0;       // slots (alive at most)
    uint32_t atlasSprites = 0;    // lit sprites that asked for an atlas rectangle
    uint32_t atlasOverflowed = 0; // ... that found no room (lit per pixel instead)
    uint32_t atlasTexels = 0;     // texels lit this frame
    uint32_t atlasSize = 0;
    std::array<uint32_t, PARTICLE_ATLAS_LODS> perLod{};
    double simulatedSeconds = 0; // simulated time at the end of the frame
};
ParticleStats readParticleStats(const Renderer& r);
// The stats JSON's "particles" object (the last frame's ParticleStats).
void particleStats(const Renderer& r, nlohmann::json& stats);

} // namespace shadel
