#pragma once
// Temporal anti-aliasing (--aa taa). The camera is jittered by a sub-pixel Halton (2, 3) offset
// every frame (16 of them, repeating); after every pass that draws into the scene colour,
// `taaResolve` accumulates this frame's colour into a history of earlier frames reprojected by
// camera motion (shaders/taa/resolve.comp: reconstruction at the unjittered pixel centre,
// disocclusion rejection by depth, variance clipping in YCoCg, an exponential blend), and
// `taaSharpen` (--taa-sharpen above 0) sharpens what is displayed. Tonemapping reads the result;
// with TAA on it is never fused into shading (render/post/tonemap.h).
//
// Motion is the camera's only: objects that move on their own (animated playback, edits) have
// no motion vectors; the depth test rejects their old pixels' history and the colour clip the
// rest.
#include <cstdint>
#include <memory>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <nlohmann/json_fwd.hpp>

#include "rhi/frame.h"

namespace shadel {

struct Renderer;
struct RenderSettings;
struct CameraView;

struct TaaState;
struct TaaStateDeleter {
    void operator()(TaaState* s) const;
};
using TaaStatePtr = std::unique_ptr<TaaState, TaaStateDeleter>;

// --aa taa (RenderSettings::aa; Auto is none here: the commands resolve it).
bool taaEnabled(const RenderSettings& settings);

// Null unless TAA is on. Throws InputError for settings it cannot work with (--ssaa above 1).
TaaStatePtr createTaa(Renderer& r);
void destroyTaa(Renderer& r, TaaStatePtr& s);

// This frame's camera: `camera` with this frame's sub-pixel jitter (remembered, with the
// unjittered view-projection, for the resolve). Before the frame's constants are made.
CameraView prepareTaaFrame(Renderer& r, const CameraView& camera);
// The next frame's camera as prepareTaaFrame will jitter it (the decoupled coarse visit run
// ahead for it, render/shadel/coarse_visit.h).
CameraView taaNextFrameView(const Renderer& r, const CameraView& camera);
// `taaResolve`, then `taaSharpen` with --taa-sharpen above 0. Before the tonemap.
void recordTaaPasses(Renderer& r, FrameRecorder& rec, uint64_t frame);
// The sampled slot of what the tonemap displays this frame (the resolved or sharpened colour).
uint32_t taaDisplaySlot(const Renderer& r);
// After the frame's submission: counters read, this frame becomes the next one's history.
void finishTaaFrame(Renderer& r);
// The history is dropped: the next frame starts accumulating anew (a camera cut).
void resetTaaHistory(Renderer& r);

// Stats "taa": sharpen, frames accumulated, last frame's rejected and clipped pixel shares.
void taaStats(const Renderer& r, nlohmann::json& stats);

// The sub-pixel offset of frame `index` of the 16-frame sequence, in pixels, and `proj` with
// it applied (the image moves by -jitter: what a pixel centre shows lies at centre + jitter in
// the unjittered image).
glm::vec2 taaJitter(uint64_t index);
glm::mat4 jitteredProjection(const glm::mat4& proj, glm::vec2 jitter, uint32_t width,
                             uint32_t height);

} // namespace shadel
