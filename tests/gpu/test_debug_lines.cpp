// 3-D debug lines (render/debug/debug_lines.h): shaders emit segments that are drawn over the
// frame; the buffer's capacity is a reported limit, never an overflow.
#include <gtest/gtest.h>

#include "core/error.h"
#include "gpu_test_env.h"
#include "render/debug/debug_lines.h"

using namespace shadel;
using namespace shadel::test;

namespace {

uint64_t lineStat(const RenderRun& run, const char* key) {
    return run.stats["debug_lines"][key].get<uint64_t>();
}

// Pixels whose colour differs between two frames.
size_t changedPixels(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
    size_t n = 0;
    for (size_t i = 0; i + 3 < a.size(); i += 4)
        n += a[i] != b[i] || a[i + 1] != b[i + 1] || a[i + 2] != b[i + 2];
    return n;
}

} // namespace

TEST(DebugLines, KindsParseAndBadKindsAreInputErrors) {
    EXPECT_EQ(parseDebugLines("none"), 0u);
    EXPECT_EQ(parseDebugLines("lights,chunks"), DEBUG_LINES_LIGHTS | DEBUG_LINES_CHUNKS);
    EXPECT_EQ(parseDebugLines("blockers"), DEBUG_LINES_BLOCKERS);
    EXPECT_THROW(parseDebugLines("lights,rays"), InputError);
    EXPECT_THROW(parseDebugLines(""), InputError);
    EXPECT_THROW(parseDebugLines(","), InputError);
}

// Light ranges, cones and blocker frusta: thin lines over an otherwise unchanged frame.
TEST(DebugLines, LightsAndBlockersAreDrawnOverTheFrame) {
    RenderOptions o = renderOptions("builtin:blockers", RenderMode::Forward, 160, 90);
    RenderRun plain = renderChecked(o);
    EXPECT_FALSE(plain.stats.contains("debug_lines"));
    o.debugLines = DEBUG_LINES_LIGHTS;
    RenderRun lights = renderChecked(o);
    o.debugLines = DEBUG_LINES_LIGHTS | DEBUG_LINES_BLOCKERS;
    RenderRun both = renderChecked(o);
    EXPECT_GT(lineStat(lights, "segments"), 0u);
    EXPECT_GT(lineStat(both, "segments"), lineStat(lights, "segments"));
    EXPECT_EQ(lineStat(both, "dropped"), 0u);
    size_t pixels = size_t(160) * 90;
    size_t changed = changedPixels(plain.frames[0].rgba, both.frames[0].rgba);
    std::printf("[ figures ] blockers 160x90: %llu segments (lights only %llu), %zu of %zu pixels "
                "changed\n",
                (unsigned long long)lineStat(both, "segments"),
                (unsigned long long)lineStat(lights, "segments"), changed, pixels);
    EXPECT_GT(changed, 0u);
    EXPECT_LT(changed, pixels / 3); // lines, not a wash over the frame
}

// builtin:lights draws ~2000 range spheres, a white web; --debug-lines-at keeps the lights that
// reach the surface at one pixel (plus a 3-segment cross there), and none at a sky pixel. In
// both paths: the depth it reads back is the prepass's or the visibility pass's.
TEST(DebugLines, PickedPixelKeepsOnlyTheLightsReachingItsSurface) {
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        RenderOptions o = renderOptions("builtin:lights", mode, 192, 108);
        o.debugLines = DEBUG_LINES_LIGHTS;
        uint64_t all = lineStat(renderChecked(o), "segments");
        o.debugLinesAtX = 96, o.debugLinesAtY = 90; // the street below the horizon
        uint64_t street = lineStat(renderChecked(o), "segments");
        o.debugLinesAtX = 96, o.debugLinesAtY = 2; // the night sky above it
        uint64_t sky = lineStat(renderChecked(o), "segments");
        std::printf("[ figures ] lights 192x108: %llu segments, %llu at the street pixel, "
                    "%llu at a sky pixel\n",
                    (unsigned long long)all, (unsigned long long)street, (unsigned long long)sky);
        EXPECT_GT(street, 3u + 24u) << "the cross and at least one light";
        EXPECT_LT(street * 10, all) << "a few lights reach one point";
        EXPECT_EQ(sky, 0u) << "nothing reaches the sky";
    }
    RenderOptions bad = renderOptions("builtin:lights", RenderMode::Forward, 192, 108);
    bad.debugLines = DEBUG_LINES_LIGHTS;
    bad.debugLinesAtX = 500, bad.debugLinesAtY = 10;
    EXPECT_THROW(runRender(sharedGpu(), bad), InputError);
    bad.debugLinesAtX = 10;
    bad.debugLines = DEBUG_LINES_CHUNKS; // no lights to pick
    EXPECT_THROW(runRender(sharedGpu(), bad), InputError);
}

// Every shaded chunk with a shadel on its surface emits its box: 12 segments each.
TEST(DebugLines, ChunkBoxesFollowTheShadedChunks) {
    RenderOptions o = renderOptions("builtin:default", RenderMode::Decoupled, 160, 90);
    o.debugLines = DEBUG_LINES_CHUNKS;
    RenderRun run = renderChecked(o);
    uint64_t segments = lineStat(run, "segments");
    uint64_t chunks = run.stats["chunks_shaded"].get<uint64_t>();
    std::printf(
        "[ figures ] default 160x90 decoupled: %llu chunk-box segments, %llu chunks shaded\n",
        (unsigned long long)segments, (unsigned long long)chunks);
    EXPECT_EQ(segments % 12, 0u);
    EXPECT_LE(segments, 12 * chunks);
    EXPECT_GE(segments, 6 * chunks); // most shaded chunks hold surface
    EXPECT_EQ(lineStat(run, "dropped"), 0u);
}

// A buffer too small for the frame: the rest is counted and dropped (validation stays clean,
// nothing is written past the end).
TEST(DebugLines, OverflowIsCountedNotWritten) {
    RenderOptions o = renderOptions("builtin:default", RenderMode::Decoupled, 160, 90);
    o.debugLines = DEBUG_LINES_CHUNKS | DEBUG_LINES_LIGHTS;
    o.debugLineCapacity = 100;
    RenderRun run = renderChecked(o);
    EXPECT_EQ(lineStat(run, "segments"), 100u);
    EXPECT_GT(lineStat(run, "dropped"), 0u);
    EXPECT_EQ(lineStat(run, "capacity"), 100u);
}
