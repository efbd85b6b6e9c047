#pragma once
// One shared lavapipe device for all GPU tests, with the Khronos validation layer on.
// Every test checks afterwards that no validation error and no shader assert happened.
#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "rhi/gpu.h"

namespace shadel::test {

Gpu& sharedGpu();
uint32_t validationErrors();

// True when the environment variable CI is set (not empty): every test must run, so a missing
// capability is a failure there. .ci/run sets it.
bool runningInCi();

// A test that needs what a machine may lack (ray query, xvfb, the assimp sample models) starts
// with SHADEL_REQUIRE(have, "what is missing"): without it the test skips on a developer's
// machine and fails under CI, naming what is missing.
#define SHADEL_REQUIRE(have, missing)                                                              \
    do {                                                                                           \
        if (!(have)) {                                                                             \
            if (::shadel::test::runningInCi())                                                     \
                GTEST_FAIL() << "CI is set and this machine lacks what the test needs: "           \
                             << missing;                                                           \
            GTEST_SKIP() << missing << " (under CI this fails)";                                   \
        }                                                                                          \
    } while (false)

// Renders and returns the run; asserts no validation errors / shader asserts were added.
RenderRun renderChecked(const RenderOptions& options);

// What an RGBA8 image shows: the share of its pixels that saw geometry (alpha > 0: the display
// pixels' alpha is their coverage) and the standard deviation of its RGB values (8-bit levels).
// A render that drew nothing has no coverage, or one flat colour.
struct ImageContent {
    double coverage = 0.0, deviation = 0.0;
    bool any() const { return coverage > 0.0 && deviation > 0.0; }
};
ImageContent imageContent(const std::vector<uint8_t>& rgba);

// PSNR of the RGB channels (99 for equal images). Comparisons of two images also check that
// at least one has content (ImageContent::any): two empty renders agree perfectly, and that
// must not pass a test. psnr, worstFramePsnr, worstFrameErrorQuantile and meanFrameDelta add
// a failure when neither image of a compared pair has content.
double psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b);

// Options for rendering `scene` in `mode` at w x h (everything else default).
RenderOptions renderOptions(const std::string& scene, RenderMode mode, uint32_t w, uint32_t h);

// A path in the temp directory private to this test process (`name` prefixed with the pid), so
// two test runs on one machine never read each other's files.
std::string tempPath(const std::string& name);

// Flicker: mean absolute difference between consecutive frames, over all colour channels.
double meanFrameDelta(const RenderRun& run);

// The JSON a run wrote to `path` (a --trace file), then the file removed; null if it is missing.
nlohmann::json takeJsonFile(const std::string& path);

// The lowest PSNR between the runs' frames of the same index (the runs have as many frames).
double worstFramePsnr(const RenderRun& a, const RenderRun& b);
// The largest, over the frames of the same index, of the `quantile` (0..1) of the per-channel
// absolute differences (RGB, 8-bit levels): what the worst frame's worst pixels are off by,
// which an average such as PSNR hides when few pixels differ much.
int worstFrameErrorQuantile(const RenderRun& a, const RenderRun& b, double quantile);

// --visualize reuse (shaders/shadel/resolve.glsl reuseReasonView): the shares of a frame's
// covered pixels whose chunk was carried over (grey: the channels equal) or shaded for each
// reason, told by its tint's dominant channels (red also counts orange: near a change).
struct ReuseViewShares {
    double carried = 0.0, notReusable = 0.0, fresh = 0.0, refresh = 0.0, view = 0.0;
};
ReuseViewShares reuseViewShares(const std::vector<uint8_t>& rgba);

// The same decoupled run with --reuse on and off (checked as renderChecked checks them).
struct ReuseRuns {
    RenderRun on, off;
};
ReuseRuns renderReuseOnAndOff(RenderOptions o);

// Test scenes written as glTF. appendBox: an axis-aligned box (centre, half extents) as 24
// vertices, 4 per face with the face's normal, and 36 indices counter-clockwise seen from
// outside, numbered from the box's first vertex (the box is its own mesh).
void appendBox(const float centre[3], const float half[3], std::vector<float>& positions,
               std::vector<float>& normals, std::vector<uint16_t>& indices);
// Writes `doc` to tempPath(NAME.gltf) with one buffer, NAME.bin beside it: `floats`, then
// `indices` (16-bit) from byte floats.size() * 4; returns the .gltf path.
std::string writeGltf(const std::string& name, nlohmann::json doc, const std::vector<float>& floats,
                      const std::vector<uint16_t>& indices);
nlohmann::json gltfBufferView(size_t byteOffset, size_t byteLength); // of buffer 0
nlohmann::json gltfAccessor(int bufferView, int componentType, int count, const char* type);
// A node rotation (quaternion x, y, z, w) turning -Z onto `direction`, +Y up: a camera or a
// light looking along it.
nlohmann::json gltfRotationTowards(glm::vec3 direction);

} // namespace shadel::test
