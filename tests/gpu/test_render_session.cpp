// A render in steps (app/commands.h: beginRender, renderNextFrame, finishRender), and the
// bench's side-by-side runs that interleave several live renders frame by frame on one device
// (--interleave N): a render must not see another's frames, slots or state.
#include "gpu_test_env.h"

#include <stdexcept>

using namespace shadel;
using namespace shadel::test;

namespace {

// Forward, decoupled and decoupled with reuse: the bench's three modes, on a moving camera so
// that reuse carries frames over.
std::vector<RenderOptions> threeModes() {
    std::vector<RenderOptions> runs;
    for (int k = 0; k < 3; ++k) {
        RenderOptions o = renderOptions(
            "builtin:default", k == 0 ? RenderMode::Forward : RenderMode::Decoupled, 96, 54);
        o.frames = 3;
        o.cameraPath = CameraPath::Orbit;
        o.reuse = k == 2;
        o.threads = 2; // the next frame's coarse visit runs beside the other runs' frames
        runs.push_back(o);
    }
    return runs;
}

} // namespace

// Three live renders taking turns frame by frame give every frame each gives alone.
TEST(RenderSession, InterleavedRendersMatchSeparateOnes) {
    std::vector<RenderOptions> runs = threeModes();
    std::vector<RenderRun> alone;
    for (const RenderOptions& o : runs) alone.push_back(renderChecked(o));

    const uint32_t errorsBefore = validationErrors();
    std::vector<RenderSessionPtr> sessions;
    for (const RenderOptions& o : runs) sessions.push_back(beginRender(sharedGpu(), o));
    for (uint32_t i = 0; i < 3; ++i)
        for (size_t n = 0; n < sessions.size(); ++n) {
            size_t k = i % 2 == 0 ? n : sessions.size() - 1 - n; // as the bench alternates
            ASSERT_FALSE(renderSessionDone(*sessions[k]));
            renderNextFrame(*sessions[k]);
        }
    for (size_t k = 0; k < sessions.size(); ++k) {
        ASSERT_TRUE(renderSessionDone(*sessions[k]));
        RenderRun together = finishRender(std::move(sessions[k]));
        ASSERT_EQ(together.frames.size(), alone[k].frames.size()) << k;
        for (size_t f = 0; f < together.frames.size(); ++f) {
            EXPECT_GE(psnr(together.frames[f].rgba, alone[k].frames[f].rgba), 60.0)
                << "run " << k << " frame " << f;
            EXPECT_EQ(together.frames[f].pixelsCovered, alone[k].frames[f].pixelsCovered);
        }
        for (const char* field : {"shadels_shaded", "shadels_reused", "chunks_allocated"})
            EXPECT_EQ(together.stats.value(field, nlohmann::json()),
                      alone[k].stats.value(field, nlohmann::json()))
                << "run " << k << " " << field;
        EXPECT_EQ(together.stats["shader_asserts"].get<uint64_t>(), 0u);
    }
    EXPECT_EQ(validationErrors(), errorsBefore);
}

// Steps out of order are errors, not a render of frames that were never asked for.
TEST(RenderSession, StepsOutOfOrderThrow) {
    RenderOptions o = renderOptions("builtin:smooth", RenderMode::Forward, 32, 18);
    o.frames = 1;
    RenderSessionPtr session = beginRender(sharedGpu(), o);
    EXPECT_THROW(finishRender(std::move(session)), std::logic_error); // a frame is left
    session = beginRender(sharedGpu(), o);
    renderNextFrame(*session);
    EXPECT_TRUE(renderSessionDone(*session));
    EXPECT_THROW(renderNextFrame(*session), std::logic_error); // no frame is left
    RenderRun run = finishRender(std::move(session));
    EXPECT_EQ(run.frames.size(), 1u);
    EXPECT_EQ(run.stats["frames"].get<uint32_t>(), 1u);
}

// The bench with its modes taking turns of frames reports what it reports with whole runs one
// after another: the same frames rendered, only their order on the device differs.
TEST(RenderSession, BenchInterleavedByFrameCountsAsRunByRun) {
    BenchOptions b;
    b.scene = "builtin:default";
    b.width = 96;
    b.height = 54;
    b.frames = 3;
    b.cameraPath = CameraPath::Orbit;
    nlohmann::json result[2];
    for (int k = 0; k < 2; ++k) {
        b.framesPerTurn = k == 0 ? 2 : 0; // turns of 2 frames (the last turn has 1), whole runs
        result[k] = runBench(sharedGpu(), b);
    }
    EXPECT_EQ(result[0]["interleave"], 2);
    EXPECT_EQ(result[1]["interleave"], "runs");
    for (const char* mode : {"forward", "decoupled", "reuse"}) {
        const nlohmann::json& a = result[0]["modes"][mode];
        const nlohmann::json& r = result[1]["modes"][mode];
        ASSERT_TRUE(a.is_object() && r.is_object()) << mode;
        for (const char* field : {"pixels_covered", "shadels_shaded", "shadels_reused", "frames"})
            EXPECT_EQ(a.value(field, nlohmann::json()), r.value(field, nlohmann::json()))
                << mode << " " << field;
        EXPECT_GT(a["frame_ms"]["median"].get<double>(), 0.0) << mode;
    }
    for (const char* ratio : {"decoupled", "reuse"})
        EXPECT_GT(result[0]["ratios"][ratio].get<double>(), 0.0) << ratio;
    EXPECT_GT(result[0]["modes"]["reuse"]["shadels_reused"].get<uint64_t>(), 0u);
    // Auto: half the frames, 1 to 4, so that 3 frames still take turns (of 1 frame).
    b.framesPerTurn = BenchOptions::kFramesPerTurnAuto;
    EXPECT_EQ(runBench(sharedGpu(), b)["interleave"], 1);
    EXPECT_EQ(validationErrors(), 0u);
}
