// Live scene edits (render/scene_edits.h; the viewer's light, sun and material editor):
// an edit made between two frames of one renderer shows in full in the next frame, in both
// paths. The decoupled path reuses last frame's shadels (preserved layers, --reuse on), so this
// checks that an edit invalidates what it reaches: without that, the carried-over chunks would
// show the old light or material.
#include "gpu_test_env.h"

#include <functional>

#include "app/commands.h"
#include "bake/bake.h"
#include "core/error.h"
#include "render/renderer.h"
#include "render/shadel/decoupled.h"
#include "render/view_density.h"
#include "scene/load.h"

using namespace shadel;
using namespace shadel::test;

namespace {

constexpr uint32_t kWidth = 160, kHeight = 90;

using Edit = std::function<void(Renderer&, const GpuScene&)>;

struct EditFrames {
    std::vector<uint8_t> before; // the second unedited frame (a reusing path reuses all of it)
    std::vector<uint8_t> after;  // the next frame, after the edit
    std::vector<uint8_t> fresh;  // a new renderer's first frame with the same edit
    uint64_t reusedAfter = 0;    // decoupled: shadels carried over into `after`
};

// builtin:default prepared as `shadel render` does for a static camera (density, bake), then
// rendered by one renderer before and after `edit`, and by a fresh one with the edit.
EditFrames renderEdit(RenderMode mode, const Edit& edit) {
    Gpu& gpu = sharedGpu();
    uint32_t errorsBefore = validationErrors();
    Scene scene = loadScene("builtin:default", {});
    Camera camera = findCamera(scene, "");
    RunViews views = runViews(camera, CameraPath::Static, 1, scene.worldBounds(), kWidth, kHeight);
    ViewDensity density = viewDrivenDensity(scene, views, {});
    scene = std::move(density.scene);
    std::vector<BakedMesh> baked;
    if (mode == RenderMode::Decoupled)
        baked = bakeScene(scene, {}, defaultCacheFolder(), nullptr, density.meshDensity);
    GpuScene gs;
    uploadScene(gpu, scene, gs, mode == RenderMode::Decoupled ? &baked : nullptr);
    RenderSettings s;
    s.width = kWidth;
    s.height = kHeight;
    s.mode = mode;
    s.reuse = true;
    s.timing = defaultTimingMode(gpu);
    CameraView view = makeCameraView(camera, kWidth, kHeight);

    EditFrames out;
    Renderer r;
    initRenderer(r, gpu, s, gs);
    renderFrame(r, gs, view);
    out.before = renderFrame(r, gs, view).rgba;
    edit(r, gs);
    FrameResult after = renderFrame(r, gs, view);
    out.after = after.rgba;
    EXPECT_EQ(after.shaderAsserts, 0u);
    if (mode == RenderMode::Decoupled) {
        nlohmann::json stats = nlohmann::json::object();
        decoupledStats(r, stats);
        out.reusedAfter = stats["shadels_reused"].get<uint64_t>();
    }
    destroyRenderer(r);

    Renderer fresh;
    initRenderer(fresh, gpu, s, gs);
    edit(fresh, gs);
    out.fresh = renderFrame(fresh, gs, view).rgba;
    destroyRenderer(fresh);
    destroyScene(gpu, gs);
    EXPECT_EQ(validationErrors(), errorsBefore);
    return out;
}

// The instance with the largest world box: its material is one the camera sees widely. With
// `plainOnly`, among materials that use no MATERIAL_FEATURE_*.
uint32_t largestMaterial(const GpuScene& gs, bool plainOnly = false) {
    uint32_t best = 0;
    float area = -1.0f;
    for (const gpu::GpuInstance& inst : gs.instanceInfo) {
        if (plainOnly && materialFeatures(gs.materialInfo[inst.material]) != 0u) continue;
        glm::vec3 e = inst.worldMax - inst.worldMin;
        float a = e.x * e.z + e.x * e.y + e.y * e.z;
        if (a > area) area = a, best = inst.material;
    }
    return best;
}

void expectEditShows(const char* what, RenderMode mode, const Edit& edit) {
    EditFrames f = renderEdit(mode, edit);
    const char* path = mode == RenderMode::Forward ? "forward" : "decoupled";
    double change = psnr(f.before, f.after), agree = psnr(f.after, f.fresh);
    std::printf("[ figures ] %s, %s: edited vs unedited %.2f dB, vs a fresh renderer %.2f dB, "
                "%llu shadels reused\n",
                what, path, change, agree, (unsigned long long)f.reusedAfter);
    EXPECT_LT(change, 35.0) << what << " (" << path << "): the edit does not show";
    EXPECT_GE(agree, 45.0) << what << " (" << path << "): stale shading after the edit";
}

} // namespace

TEST(SceneEdits, MaterialEditShowsInTheNextFrameBothPaths) {
    Edit recolour = [](Renderer& r, const GpuScene& gs) {
        uint32_t index = largestMaterial(gs);
        gpu::GpuMaterial m = currentMaterial(r, gs, index);
        m.baseColorFactor = glm::vec4(0.9f, 0.15f, 0.1f, m.baseColorFactor.w);
        m.roughnessFactor = 0.3f;
        editMaterial(r, gs, index, m);
    };
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled})
        expectEditShows("material", mode, recolour);
}

// A plain material given a clear coat and a sheen: its surfaces leave the pipelines compiled
// without material features (forward: DRAW_LIST_OPAQUE's; shadel path: the plain class) for the
// all-features ones, else the edit would not show.
TEST(SceneEdits, MaterialEditAddingFeaturesShowsBothPaths) {
    Edit coat = [](Renderer& r, const GpuScene& gs) {
        uint32_t index = largestMaterial(gs, true);
        gpu::GpuMaterial m = currentMaterial(r, gs, index);
        ASSERT_EQ(materialFeatures(m), 0u);
        m.clearcoatFactor = 1.0f;
        m.clearcoatRoughnessFactor = 0.05f;
        m.sheenColorFactor = glm::vec3(1.0f, 0.1f, 0.9f);
        m.sheenRoughnessFactor = 0.4f;
        editMaterial(r, gs, index, m);
        EXPECT_NE(currentMaterial(r, gs, index).flags & MATERIAL_FEATURED, 0u);
    };
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled})
        expectEditShows("material features", mode, coat);
}

TEST(SceneEdits, LightAndSunEditsShowInTheNextFrameBothPaths) {
    // Every point or spot light five times brighter and tinted: each reaches only its range, so
    // the decoupled path reshades only the chunks inside.
    Edit lights = [](Renderer& r, const GpuScene& gs) {
        for (uint32_t i = 0; i < gs.lightInfo.size(); ++i) {
            gpu::GpuLight l = currentLight(r, gs, i);
            l.color *= glm::vec3(5.0f, 2.0f, 1.0f);
            editLight(r, gs, i, l);
        }
    };
    Edit sun = [](Renderer& r, const GpuScene& gs) {
        SunEdit s = currentSun(r, gs);
        s.direction = glm::normalize(s.direction + glm::vec3(0.4f, 0.0f, 0.3f)); // shadows move
        s.color *= 0.5f;
        editSun(r, s);
    };
    for (RenderMode mode : {RenderMode::Forward, RenderMode::Decoupled}) {
        expectEditShows("lights", mode, lights);
        expectEditShows("sun", mode, sun);
    }
}

// The viewer switches its debug view between two frames of one renderer (renderer.settings),
// as the edits above change the scene: --visualize reuse, whose per-slot reasons the renderer
// makes only once a frame shows the view, shows in the next frame. A still camera carries every
// chunk over (grey, the channels equal) but the few due for their refresh; a fresh renderer's
// first frame has nothing to carry (red: not reusable).
TEST(SceneEdits, ReuseViewSwitchedOnBetweenFrames) {
    EditFrames f = renderEdit(RenderMode::Decoupled, [](Renderer& r, const GpuScene&) {
        r.settings.visualize = Visualize::Reuse;
    });
    double greyBefore = reuseViewShares(f.before).carried;
    double greyAfter = reuseViewShares(f.after).carried;
    double redFresh = reuseViewShares(f.fresh).notReusable;
    std::printf("[ figures ] reuse view switched on: grey pixels %.3f before, %.3f after; a fresh "
                "renderer's first frame %.3f red\n",
                greyBefore, greyAfter, redFresh);
    EXPECT_GT(greyAfter, 0.8);
    EXPECT_GT(greyAfter, greyBefore + 0.3);
    EXPECT_GT(redFresh, 0.9);
}

TEST(SceneEdits, OutOfRangeIndexIsAnInputError) {
    Gpu& gpu = sharedGpu();
    Scene scene = loadScene("builtin:smooth", {});
    GpuScene gs;
    uploadScene(gpu, scene, gs);
    RenderSettings s;
    s.width = 32;
    s.height = 18;
    Renderer r;
    initRenderer(r, gpu, s, gs);
    EXPECT_THROW(editLight(r, gs, uint32_t(gs.lightInfo.size()), gpu::GpuLight{}), InputError);
    EXPECT_THROW(editMaterial(r, gs, uint32_t(gs.materialInfo.size()), gpu::GpuMaterial{}),
                 InputError);
    destroyRenderer(r);
    destroyScene(gpu, gs);
}
