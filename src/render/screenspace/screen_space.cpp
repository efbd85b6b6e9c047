#include "render/screenspace/screen_space.h"

#include <algorithm>

#include "core/error.h"
#include "core/log.h"
#include "render/renderer.h"
#include "render/screenspace/thin_gbuffer.h"
#include "render/tiles/tile_classification.h"
#include "screenspace/screen_space_types.h"

namespace shadel {

struct ScreenSpaceState {
    ThinGBuffer gbuffer;
    TileClassification tiles;
    TextureHandle reflection, sss0, sss1, pyramid;
    TextureWriteView hdrWrite, ssrWrite, sss0Write, sss1Write;
    TextureWriteView pyramidLevels[DEPTH_PYRAMID_LEVELS];
    uint32_t levels = 0;
    Pipeline buildPyramid, sky, skyAllSky, ssrTrace, ssrClear, sssDownsample, sssBlurH, sssBlurV,
        composite, distanceFieldLighting;
    bool classified = false; // this frame ran the classification (counts to read back)
};

void ScreenSpaceStateDeleter::operator()(ScreenSpaceState* s) const {
    delete s;
}

namespace {
constexpr VkPipelineStageFlags2 kCompute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
constexpr VkAccessFlags2 kReadWrite = VK_ACCESS_2_SHADER_STORAGE_READ_BIT |
                                      VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |
                                      VK_ACCESS_2_SHADER_SAMPLED_READ_BIT;

void computeBarrier(VkCommandBuffer cmd) {
    memoryBarrier(cmd, kCompute, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, kCompute, kReadWrite);
}

TextureHandle storageTexture(Gpu& gpu, const char* name, VkFormat pixelFormat, uint32_t w,
                             uint32_t h, uint32_t mips = 1) {
    TextureDesc d;
    d.name = name;
    d.format = pixelFormat;
    d.width = w;
    d.height = h;
    d.mipLevels = mips;
    d.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
              VK_IMAGE_USAGE_TRANSFER_SRC_BIT; // --capture
    TextureHandle t = createTexture(gpu, d);
    if (!t) throw DeviceError(format("out of GPU memory for %s", name));
    return t;
}

void destroyState(Renderer& r, ScreenSpaceState& s) {
    Gpu& gpu = *r.gpu;
    destroyThinGBuffer(r, s.gbuffer);
    destroyTileClassification(gpu, s.tiles);
    for (Pipeline* p :
         {&s.buildPyramid, &s.sky, &s.skyAllSky, &s.ssrTrace, &s.ssrClear, &s.sssDownsample,
          &s.sssBlurH, &s.sssBlurV, &s.composite, &s.distanceFieldLighting})
        destroy(gpu, *p);
    for (TextureWriteView v : {s.hdrWrite, s.ssrWrite, s.sss0Write, s.sss1Write}) destroy(gpu, v);
    for (uint32_t i = 0; i < s.levels; ++i) destroy(gpu, s.pyramidLevels[i]);
    for (TextureHandle t : {s.reflection, s.sss0, s.sss1, s.pyramid}) destroy(gpu, t);
}

gpu::ScreenSpacePush makePush(Renderer& r, const ScreenSpaceState& s, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    gpu::ScreenSpacePush p{};
    p.frame = frame;
    p.tiles = address(gpu, s.tiles.buffer);
    p.listOffset = TILE_LIST_ALL;
    p.width = r.internalWidth;
    p.height = r.internalHeight;
    p.depthSlot = slot(gpu, r.depthRead).value;
    p.normalSlot = slot(gpu, s.gbuffer.normalRead).value;
    p.flagsSlot = slot(gpu, s.gbuffer.flagsRead).value;
    p.hdrSlot = slot(gpu, s.hdrWrite).value;
    p.ssrSlot = slot(gpu, s.ssrWrite).value;
    p.sssSlot0 = slot(gpu, s.sss0Write).value;
    p.sssSlot1 = slot(gpu, s.sss1Write).value;
    p.tilesX = s.tiles.tilesX;
    for (uint32_t i = 0; i < DEPTH_PYRAMID_LEVELS; ++i)
        p.pyramid[i] = slot(gpu, s.pyramidLevels[std::min(i, s.levels - 1)]).value;
    if (r.distanceFields) {
        p.distanceFields = distanceFieldFrameAddress(r, *r.distanceFields);
        p.dfSlot = distanceFieldOutputSlot(r, *r.distanceFields);
    }
    if (r.stencilEffects) {
        p.stencilEffects = 1;
        p.characterMaskSlot = characterMaskSlot(r, *r.stencilEffects);
    }
    return p;
}

// Runs `pipeline` over the tiles of `list` (classification on) or over every tile.
void dispatchPass(Renderer& r, ScreenSpaceState& s, VkCommandBuffer cmd, const Pipeline& pipeline,
                  gpu::ScreenSpacePush push, uint32_t list) {
    Gpu& gpu = *r.gpu;
    bind(gpu, cmd, pipeline);
    bool classified = r.settings.tileClassification;
    push.listOffset = classified ? tileListOffset(s.tiles, list) : TILE_LIST_ALL;
    pushConstants(gpu, cmd, push);
    if (classified)
        dispatchTileList(gpu, cmd, s.tiles, list);
    else
        dispatchAllTiles(cmd, s.tiles);
}
} // namespace

void createScreenSpace(Renderer& r) {
    if (!r.settings.screenSpace) return;
    if (r.settings.mode == RenderMode::Decoupled && r.settings.marking == MarkingMode::Visibility)
        throw InputError("--screen-space on needs --marking raster (the visibility resolve keeps "
                         "the scene colour in another layout)");
    Gpu& gpu = *r.gpu;
    auto s = ScreenSpaceStatePtr(new ScreenSpaceState);
    uint32_t w = r.internalWidth, h = r.internalHeight;
    s->gbuffer = createThinGBuffer(r);
    s->tiles = createTileClassification(gpu, w, h);
    s->reflection = storageTexture(gpu, "ssr.reflection", VK_FORMAT_R16G16B16A16_SFLOAT, w, h);
    s->sss0 =
        storageTexture(gpu, "sss.half0", VK_FORMAT_R16G16B16A16_SFLOAT, (w + 1) / 2, (h + 1) / 2);
    s->sss1 =
        storageTexture(gpu, "sss.half1", VK_FORMAT_R16G16B16A16_SFLOAT, (w + 1) / 2, (h + 1) / 2);
    uint32_t levels = 1;
    while (levels < DEPTH_PYRAMID_LEVELS && (std::max(w, h) >> levels) > 0) ++levels;
    s->levels = levels;
    s->pyramid = storageTexture(gpu, "ssr.depthPyramid", VK_FORMAT_R32_UINT, w, h, levels);
    s->hdrWrite = createWriteView(gpu, r.hdr);
    s->ssrWrite = createWriteView(gpu, s->reflection);
    s->sss0Write = createWriteView(gpu, s->sss0);
    s->sss1Write = createWriteView(gpu, s->sss1);
    for (uint32_t i = 0; i < levels; ++i)
        s->pyramidLevels[i] = createWriteView(gpu, s->pyramid, ViewDesc{i, 1});
    s->buildPyramid =
        createComputePipeline(gpu, "depthPyramid", "screenspace_depth_pyramid.comp.spv");
    s->sky = createComputePipeline(gpu, "sky", "screenspace_sky.comp.spv", {{0, 0u}});
    s->skyAllSky = createComputePipeline(gpu, "skyAllSky", "screenspace_sky.comp.spv", {{0, 1u}});
    s->ssrTrace = createComputePipeline(gpu, "ssr", "screenspace_ssr.comp.spv", {{0, 0u}});
    s->ssrClear = createComputePipeline(gpu, "ssrClear", "screenspace_ssr.comp.spv", {{0, 1u}});
    s->sssDownsample =
        createComputePipeline(gpu, "sssDownsample", "screenspace_sss_downsample.comp.spv");
    s->sssBlurH =
        createComputePipeline(gpu, "sssBlurH", "screenspace_sss_blur.comp.spv", {{0, 0u}});
    s->sssBlurV =
        createComputePipeline(gpu, "sssBlurV", "screenspace_sss_blur.comp.spv", {{0, 1u}});
    s->composite =
        createComputePipeline(gpu, "screenSpaceComposite", "screenspace_composite.comp.spv");
    s->distanceFieldLighting =
        createComputePipeline(gpu, "distanceFieldLighting", "distance_fields_df_lighting.comp.spv");
    ScreenSpaceState* state = s.get();
    registerTextureCapture(
        r.captures, gpu, "gbuffer.normal",
        "thin G-buffer: world normal (rgb) + roughness (a) (EXR)", CaptureKind::Hdr,
        [state] { return state->gbuffer.normalRoughness; },
        VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    registerTextureCapture(
        r.captures, gpu, "ssr", "screen-space reflections: radiance (rgb) + weight (a) (EXR)",
        CaptureKind::Hdr, [state] { return state->reflection; }, VK_IMAGE_LAYOUT_GENERAL);
    r.screenSpace = std::move(s);
}

void destroyScreenSpace(Renderer& r) {
    if (!r.screenSpace) return;
    destroyState(r, *r.screenSpace);
    r.screenSpace.reset();
}

void recordThinGBufferPass(Renderer& r, FrameRecorder& rec, uint64_t frame) {
    if (!r.screenSpace) return;
    pass(rec, "thinGBuffer", [&, frame](VkCommandBuffer cmd) {
        recordThinGBuffer(r, r.screenSpace->gbuffer, cmd, frame);
    });
}

void recordScreenSpacePasses(Renderer& r, FrameRecorder& rec, uint64_t frame) {
    if (!r.screenSpace) return;
    ScreenSpaceState& s = *r.screenSpace;
    Gpu& gpu = *r.gpu;
    gpu::ScreenSpacePush push = makePush(r, s, frame);
    bool on = r.settings.tileClassification;
    s.classified = on || r.settings.visualize == Visualize::Tiles;

    pass(rec, "depthPyramid", [&, push](VkCommandBuffer cmd) {
        // The lit image becomes a storage image and the depth a sampled one until the end of
        // the screen-space passes; the intermediate targets start undefined every frame.
        imageBarrier(cmd, vkImage(gpu, r.hdr), VK_IMAGE_ASPECT_COLOR_BIT,
                     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                     VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                     VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, kCompute, kReadWrite);
        imageBarrier(cmd, vkImage(gpu, r.depth), VK_IMAGE_ASPECT_DEPTH_BIT,
                     VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                     VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                     VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                         VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, kCompute,
                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
        for (TextureHandle t : {s.reflection, s.sss0, s.sss1, s.pyramid})
            imageBarrier(cmd, vkImage(gpu, t), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                         VK_IMAGE_LAYOUT_GENERAL, kCompute, kReadWrite, kCompute, kReadWrite);
        bind(gpu, cmd, s.buildPyramid);
        gpu::ScreenSpacePush levelPush = push;
        for (uint32_t level = 0; level < s.levels; ++level) {
            levelPush.level = level;
            pushConstants(gpu, cmd, levelPush);
            uint32_t w = std::max(r.internalWidth >> level, 1u);
            uint32_t h = std::max(r.internalHeight >> level, 1u);
            vkCmdDispatch(cmd, (w + 7) / 8, (h + 7) / 8, 1);
            computeBarrier(cmd);
        }
    });
    if (s.classified)
        pass(rec, "tileClassify",
             [&, push](VkCommandBuffer cmd) { recordTileClassification(gpu, cmd, s.tiles, push); });
    pass(rec, "ssr", [&, push, on](VkCommandBuffer cmd) {
        dispatchPass(r, s, cmd, s.ssrTrace, push, TILE_LIST_SSR);
        if (on) dispatchPass(r, s, cmd, s.ssrClear, push, TILE_LIST_SSR_CLEAR);
        computeBarrier(cmd);
    });
    pass(rec, "sss", [&, push](VkCommandBuffer cmd) {
        dispatchPass(r, s, cmd, s.sssDownsample, push, TILE_LIST_SSS);
        computeBarrier(cmd);
        dispatchPass(r, s, cmd, s.sssBlurH, push, TILE_LIST_SSS);
        computeBarrier(cmd);
        dispatchPass(r, s, cmd, s.sssBlurV, push, TILE_LIST_SSS);
        computeBarrier(cmd);
    });
    if (r.distanceFields)
        pass(rec, "distanceFieldLighting", [&, push](VkCommandBuffer cmd) {
            beginDistanceFieldOutput(r, *r.distanceFields, cmd);
            dispatchPass(r, s, cmd, s.distanceFieldLighting, push, TILE_LIST_SURFACE);
            recordDistanceFieldReadback(r, *r.distanceFields, cmd);
            computeBarrier(cmd);
        });
    pass(rec, "sky", [&, push, on](VkCommandBuffer cmd) {
        if (on) dispatchPass(r, s, cmd, s.skyAllSky, push, TILE_LIST_SKY);
        dispatchPass(r, s, cmd, s.sky, push, TILE_LIST_SKY_EDGE);
        computeBarrier(cmd);
    });
    pass(rec, "screenSpaceComposite", [&, push](VkCommandBuffer cmd) {
        dispatchPass(r, s, cmd, s.composite, push, TILE_LIST_SURFACE);
        computeBarrier(cmd);
        if (r.settings.visualize == Visualize::Tiles) {
            bind(gpu, cmd, s.tiles.visualize);
            pushConstants(gpu, cmd, push);
            dispatchAllTiles(cmd, s.tiles);
            computeBarrier(cmd);
        }
        if (s.classified) recordTileCountReadback(gpu, cmd, s.tiles);
        // Back to what the passes after (transparency, tonemap) expect.
        imageBarrier(cmd, vkImage(gpu, r.hdr), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
                     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, kCompute, kReadWrite,
                     VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                     VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
                         VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT);
        imageBarrier(cmd, vkImage(gpu, r.depth), VK_IMAGE_ASPECT_DEPTH_BIT,
                     VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                     VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, kCompute,
                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                     VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                         VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                         VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
    });
}

gpu::ScreenSpacePush screenSpacePush(Renderer& r, uint64_t frame) {
    return makePush(r, *r.screenSpace, frame);
}

void finishScreenSpaceFrame(Renderer& r) {
    if (r.distanceFields) finishDistanceFieldFrame(r, *r.distanceFields);
    if (!r.screenSpace || !r.screenSpace->classified) return;
    readTileCounts(*r.gpu, r.screenSpace->tiles);
}

void screenSpaceStats(const Renderer& r, nlohmann::json& stats) {
    if (!r.screenSpace) return;
    const ScreenSpaceState& s = *r.screenSpace;
    stats["tile_classification"] = r.settings.tileClassification ? "on" : "off";
    nlohmann::json classes;
    classes["tiles"] = s.tiles.tilesX * s.tiles.tilesY;
    if (s.classified)
        for (uint32_t i = 0; i < TILE_LIST_COUNT; ++i) classes[tileListName(i)] = s.tiles.counts[i];
    stats["tile_classes"] = classes;
}

} // namespace shadel
