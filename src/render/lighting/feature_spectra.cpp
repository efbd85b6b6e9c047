#include "render/lighting/feature_spectra.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"
#include "render/renderer.h"
#include "render/shadel/decoupled.h"

namespace shadel {

namespace {
// The shading modes, cheapest first; a tile takes the first that covers its features, and the
// last has every feature, so every tile finds one. Chosen from the tiles' exact feature sets on
// builtin:lights at 1280x720 (stats "tile_feature_sets": sky 461 tiles, the moon's shadow alone
// 107, the spot kinds 269, with tubes 320, with darks / clip planes 233, with spot shadows 323,
// soft 617, with blockers and portals 780): few modes, because each is one more pipeline to
// compile, and a tile in a mode wider than it needs pays for the superfluous features (stats
// "spectra_superfluous").
// Measured (shadel bench --scene builtin:lights --size 1280x720 --spectra compare, lavapipe):
// frame medians spectra / single all-features permutation 1.037 (3 frames) and 0.934 (5 frames,
// machine loaded), tile shading / raster forward 0.895 and 0.976: no clear gain from spectra
// here. What permutations gain on a GPU is occupancy (fewer registers per thread); a CPU
// rasterizer has no such limit, and a tile's features are uniform across its workgroup, so
// branches for features it lacks are already skipped at run time.
// Measured at the pass (bench --spectra compare --timing submit: on and single in two rounds of
// opposite order, shading = the tile pass + tile shading, or the chunk classify + shadel
// shading), 1280x720, 8 frames, machine shared (load 6.7-7.5 on 2 cores): forward frame
// on / single 1.000 and 0.945, shading passes 0.987 and 0.933 (two runs of the same shaders);
// decoupled shading 1.019 before and 0.969 after the permutations read the classify phase's
// lists (shading sum 1581 -> 1260 ms on, 1552 -> 1300 ms single; frame on / off 1.311 -> 1.091).
// Why the permutations do not pay here (builtin:lights 640x360, forward): the same bins shaded
// by all-features pipelines cost the same per ms of the tile pass (tileShading 136/138 ms with
// lightCulling 59 ms, against 165/167 ms with 75 ms); a never-taken branch of 200 sin() per
// light added at most ~15%, so llvmpipe jumps over what a light does not use; reading the
// tile's list from a workgroup-uniform index changed nothing; without lights the tile shading
// costs ~25 of ~215 ms, the rest is the lights each pixel does need (BRDF, spot shadows; area
// lights ~10%). Granularity cannot help where the work is needed: 325 of 920 tiles (640x360)
// have per-pixel blocker pairs and with them nearly every other feature.
// Gobos and textured area lights (a texture read per light, area lights a 4x4 integral) are
// the costliest kinds: modes add area lights alone, and both, to the street's lights
// (builtin:textured-lights' lit tiles take the street's: tubes, darks and clip planes cost
// little) and to its shadowed spots, so tiles without them never carry their code.
// Material features are a spectrum feature too (SPECTRUM_MATERIAL: textures, procedurals,
// clear coat, sheen, the supersampling of procedurals in the shadel path): the tile pass ORs
// its pixels' materials (visibility buffer), a chunk takes its object's. Compiled in, they cost
// every pixel of the all-features permutation whether its material uses them or not, as do
// spot shadows, PCSS, gobos and area lights (what llvmpipe runs of a branch no lane takes):
// builtin:lights 1280x720 forward, one all-features mode 343 ms of tile shading, without
// material features 325, and without spot shadows, PCSS, gobos and area lights too 235 (the
// image then wrong: a measure only). Most of the street's surfaces are plain, so every mode
// but three has no material features, and a blocked tile without spot shadows has its own mode
// (353 of 3600 tiles at 1280x720). Each mode with material features follows the same mode
// without them: a tile never runs them needlessly.
constexpr uint32_t kSpots = SPECTRUM_OMNI | SPECTRUM_SPOT | SPECTRUM_SQUARE_SPOT | SPECTRUM_SHADOWS;
constexpr uint32_t kStreet = kSpots | SPECTRUM_TUBE | SPECTRUM_DARK | SPECTRUM_CLIP_PLANES;
constexpr uint32_t kShadowedStreet = kStreet | SPECTRUM_SPOT_SHADOWS | SPECTRUM_SOFT_SHADOWS;
constexpr uint32_t kTextured = SPECTRUM_PROJECTED | SPECTRUM_AREA; // lights reading textures
constexpr uint32_t kBlocked = SPECTRUM_BLOCKERS | SPECTRUM_PORTALS;
const uint32_t kSpectrumModes[] = {
    0u,                                          // sky, or only the ambient reaches the tile
    SPECTRUM_SHADOWS,                            // the sun (moon) alone
    kSpots,                                      // punctual lights
    kSpots | SPECTRUM_MATERIAL,                  // ... on textured / procedural materials
    kSpots | SPECTRUM_TUBE,                      // and tubes
    kStreet,                                     // and darks, clip planes
    kStreet | SPECTRUM_AREA,                     // and textured area lights
    kStreet | kTextured,                         // and gobos
    kStreet | SPECTRUM_AREA | SPECTRUM_MATERIAL, // ... on textured / procedural materials
    kStreet | SPECTRUM_SPOT_SHADOWS,             // the street and shadowed spots (PCF)
    kShadowedStreet,                             // and PCSS
    kShadowedStreet | kTextured,                 // and gobos, textured area lights
    kStreet | kTextured | kBlocked,              // blockers and portals, no spot shadows
    SPECTRUM_ALL_LIGHTING,                       // every lighting feature
    SPECTRUM_ALL,                                // and material features
};

const char* const kFeatureNames[SPECTRUM_FEATURE_COUNT] = {
    "omni",    "spot",    "square_spot",  "tube",         "dark",      "clip_planes", "blockers",
    "portals", "shadows", "spot_shadows", "soft_shadows", "projected", "area",        "material"};

std::string modeName(uint32_t features) {
    if (features == 0u) return "nothing_special";
    if (features == SPECTRUM_ALL) return "all";
    if (features == SPECTRUM_ALL_LIGHTING) return "all_but_material";
    std::string name;
    for (uint32_t bit = 0; bit < SPECTRUM_FEATURE_COUNT; ++bit)
        if (features & (1u << bit)) {
            if (!name.empty()) name.push_back('+');
            name.append(kFeatureNames[bit]);
        }
    return name;
}

// The material features a mode's permutation compiles in (kMaterialFeatures of
// shaders/common/material.glsl): all of them with SPECTRUM_MATERIAL, else none.
uint32_t modeMaterialFeatures(uint32_t mode) {
    return (mode & SPECTRUM_MATERIAL) ? MATERIAL_FEATURES_ALL : 0u;
}

// Whether a forward tile mode's permutation shades its list's lights that read no texture in a
// loop of their own (spectra per light, SPECTRUM_LIGHT_SPLIT_CONSTANT_ID; the raster forward
// pass does where forwardSplitsTileLights): with --spectra on, where the mode has such features
// at all. --spectra single stays the one all-features loop it is measured as. Not in the shadel
// path: its chunk lists are in shared memory, read at an index uniform over the workgroup, and
// there the split changed nothing measurable (builtin:lights 1280x720, shadelShading on
// 318-362 ms against 332-354 without it) while doubling the light loop each permutation
// compiles.
uint32_t lightSplitOf(const Renderer& r, uint32_t mode) {
    return r.settings.spectra == Spectra::On && (mode & SPECTRUM_SAMPLING_LIGHTS) != 0u;
}

struct TileShadePush {
    uint64_t frame;
    uint32_t visibilitySlot;
    uint32_t hdrSlot;
};
} // namespace

struct SpectraState {
    bool chunks = false;           // the shadel path's chunk queue (else forward screen tiles)
    std::vector<uint32_t> modes;   // feature sets, cheapest first
    std::vector<Pipeline> shading; // one permutation per mode
    Pipeline classify, setup;      // chunks: the classify pass, the dispatch sizes
    Pipeline longLists;            // chunks: the lists classify leaves (chunk_long_lists.comp)
    BufferHandle frame;            // gpu::SpectraFrame (upload)
    // Per mode: tiles, a VkDispatchIndirectCommand (x counts); chunks, a uvec4 (w counts).
    BufferHandle dispatch;     // (read back for stats)
    BufferHandle tileBins;     // modes x tiles (or chunks of the shading queue)
    BufferHandle superfluous;  // modes x features (readback)
    BufferHandle featureTiles; // features (readback)
    // Chunks: the classify pass's light lists (pool, per-chunk ranges, the pool's counter).
    BufferHandle chunkLists, chunkRanges, chunkListCount;
    BufferHandle longChunks; // the long-list pass's chunks and boxes
    uint32_t chunkListCapacity = 0;
    uint32_t tiles = 0;
    // Last frame's counts.
    std::vector<uint32_t> binned, lastSuperfluous, lastFeatureTiles;
    uint32_t lastChunkListEntries = 0, lastChunksPoolOverflow = 0, lastChunksLongLists = 0;
};

void SpectraStateDeleter::operator()(SpectraState* state) const {
    delete state;
}

bool usesTileShading(const Renderer& r) {
    return r.settings.mode == RenderMode::Forward && r.settings.spectra != Spectra::Off;
}

bool usesChunkSpectra(const Renderer& r) {
    return r.settings.mode == RenderMode::Decoupled && r.settings.spectra != Spectra::Off;
}

namespace {
uint32_t dispatchStride(const SpectraState& s) {
    return s.chunks ? 16u : 12u;
}
} // namespace

SpectraStatePtr createFeatureSpectra(Renderer& r) {
    Gpu& gpu = *r.gpu;
    SpectraStatePtr s(new SpectraState);
    if (r.settings.spectra == Spectra::Single)
        s->modes = {SPECTRUM_ALL};
    else
        s->modes.assign(std::begin(kSpectrumModes), std::end(kSpectrumModes));
    static_assert(std::size(kSpectrumModes) <= SPECTRUM_MAX_MODES);
    uint32_t modes = uint32_t(s->modes.size());
    s->chunks = usesChunkSpectra(r);
    s->tiles = s->chunks ? shadelShadingQueue(r).capacity
                         : ((r.internalWidth + LIGHT_TILE_SIZE - 1) / LIGHT_TILE_SIZE) *
                               ((r.internalHeight + LIGHT_TILE_SIZE - 1) / LIGHT_TILE_SIZE);
    auto need = [](BufferHandle b) {
        if (!b) throw DeviceError("out of GPU memory for the feature spectra buffers");
        return b;
    };
    s->frame = need(
        createBuffer(gpu, {"spectra.frame", sizeof(gpu::SpectraFrame), 0, MemoryKind::Upload}));
    s->dispatch =
        need(createBuffer(gpu, {"spectra.dispatch", uint64_t(modes) * dispatchStride(*s),
                                VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, MemoryKind::Readback}));
    s->tileBins = need(createBuffer(gpu, {"spectra.tileBins", uint64_t(modes) * s->tiles * 4}));
    s->superfluous =
        need(createBuffer(gpu, {"spectra.superfluous", uint64_t(modes) * SPECTRUM_FEATURE_COUNT * 4,
                                0, MemoryKind::Readback}));
    s->featureTiles = need(
        createBuffer(gpu, {"spectra.featureTiles", (SPECTRUM_FEATURE_COUNT + SPECTRUM_ALL + 1) * 4,
                           0, MemoryKind::Readback}));
    if (s->chunks) {
        // The classify pass culls each chunk's lights; the shading permutations read its list
        // back instead of culling again (on builtin:lights at 1280x720 that culling was a third
        // of the classify pass). 8 entries per queue slot: 13.7 (light, chunk) pairs per shaded
        // chunk there, and the queue holds far more chunks than a frame shades; a chunk whose
        // list does not fit takes every light in its permutation (the same sum, slower).
        s->chunkListCapacity = s->tiles * 8u;
        s->chunkLists =
            need(createBuffer(gpu, {"spectra.chunkLists", uint64_t(s->chunkListCapacity) * 8, 0}));
        s->chunkRanges =
            need(createBuffer(gpu, {"spectra.chunkRanges", uint64_t(s->tiles) * 8, 0}));
        s->chunkListCount = need(createBuffer(
            gpu, {"spectra.chunkListCount", SPECTRA_CHUNK_LIST_COUNTS * 4,
                  VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, MemoryKind::Readback})); // SpectraFrame
        s->longChunks = need(createBuffer(gpu, {"spectra.longChunks", uint64_t(s->tiles) * 32, 0}));
        // Permutations of the shadel shading itself (shade.comp), with its other constants.
        std::vector<std::pair<uint32_t, uint32_t>> base;
        if (r.settings.distanceFieldLighting)
            base.push_back({DISTANCE_FIELD_LIGHTING_CONSTANT_ID, 1u});
        // The renderer's optional parts, less the chunk culling: a permutation reads its
        // chunk's list from classify's pool. (A part's barriers, compiled in, would make
        // lavapipe run every permutation as coroutines.)
        base.push_back({SHADE_OPTIONAL_CONSTANT_ID,
                        shadelShadingQueue(r).shadeOptional & ~SHADE_OPTIONAL_CHUNK_LIGHTS});
        // Every permutation at once: compiled side by side (rhi/pipeline.h).
        std::vector<ComputePipelineDesc> descs;
        descs.push_back({"shadelChunkSpectra.classify", "lighting_chunk_classify.comp.spv", {}});
        descs.push_back({"shadelChunkSpectra.setup", "lighting_chunk_spectra_setup.comp.spv", {}});
        descs.push_back({"shadelChunkSpectra.longLists", "lighting_chunk_long_lists.comp.spv", {}});
        for (uint32_t m = 0; m < modes; ++m) {
            auto constants = base;
            constants.push_back({CHUNK_SPECTRA_PHASE_CONSTANT_ID, 2u});
            constants.push_back({SPECTRUM_FEATURES_CONSTANT_ID, s->modes[m]});
            constants.push_back({SPECTRUM_MODE_CONSTANT_ID, m});
            constants.push_back({MATERIAL_FEATURES_CONSTANT_ID, modeMaterialFeatures(s->modes[m])});
            descs.push_back(
                {"shadelShading." + modeName(s->modes[m]), "shadel_shade.comp.spv", constants});
        }
        std::vector<Pipeline> built = createComputePipelines(gpu, descs);
        s->classify = built[0];
        s->setup = built[1];
        s->longLists = built[2];
        s->shading.assign(built.begin() + 3, built.end());
        return s;
    }
    std::vector<ComputePipelineDesc> descs;
    for (uint32_t m = 0; m < modes; ++m)
        descs.push_back({"tileShading." + modeName(s->modes[m]),
                         "lighting_tile_shade.comp.spv",
                         {{SPECTRUM_FEATURES_CONSTANT_ID, s->modes[m]},
                          {SPECTRUM_MODE_CONSTANT_ID, m},
                          {MATERIAL_FEATURES_CONSTANT_ID, modeMaterialFeatures(s->modes[m])},
                          {SPECTRUM_LIGHT_SPLIT_CONSTANT_ID, lightSplitOf(r, s->modes[m])}}});
    s->shading = createComputePipelines(gpu, descs);
    return s;
}

void destroyFeatureSpectra(Renderer& r, SpectraStatePtr& state) {
    if (!state) return;
    Gpu& gpu = *r.gpu;
    for (Pipeline& p : state->shading) destroy(gpu, p);
    if (state->chunks) {
        destroy(gpu, state->classify);
        destroy(gpu, state->setup);
        destroy(gpu, state->longLists);
        for (BufferHandle b :
             {state->chunkLists, state->chunkRanges, state->chunkListCount, state->longChunks})
            destroy(gpu, b);
    }
    for (BufferHandle b :
         {state->frame, state->dispatch, state->tileBins, state->superfluous, state->featureTiles})
        destroy(gpu, b);
    state.reset();
}

uint64_t prepareFeatureSpectra(Renderer& r, uint32_t tilesX, uint32_t tilesY) {
    if (!r.spectra) return 0;
    Gpu& gpu = *r.gpu;
    SpectraState& s = *r.spectra;
    gpu::SpectraFrame f{};
    f.dispatch = address(gpu, s.dispatch);
    f.tileBins = address(gpu, s.tileBins);
    f.superfluous = address(gpu, s.superfluous);
    f.featureTiles = address(gpu, s.featureTiles);
    f.modeCount = uint32_t(s.modes.size());
    f.binCapacity = s.chunks ? s.tiles : tilesX * tilesY;
    if (s.chunks) {
        f.chunkLists = address(gpu, s.chunkLists);
        f.chunkRanges = address(gpu, s.chunkRanges);
        f.chunkListCount = address(gpu, s.chunkListCount);
        f.longChunks = address(gpu, s.longChunks);
        f.chunkListCapacity = s.chunkListCapacity;
    }
    for (size_t m = 0; m < s.modes.size(); ++m) f.modeFeatures[m] = s.modes[m];
    std::memcpy(mapped(gpu, s.frame), &f, sizeof(f));
    return address(gpu, s.frame);
}

void recordSpectraReset(Renderer& r, VkCommandBuffer cmd) {
    if (!r.spectra) return;
    Gpu& gpu = *r.gpu;
    SpectraState& s = *r.spectra;
    std::vector<uint32_t> args;
    for (size_t m = 0; m < s.modes.size(); ++m)
        if (s.chunks)
            args.insert(args.end(), {0u, 0u, 1u, 0u}); // sized by the setup after classifying
        else
            args.insert(args.end(), {0u, 1u, 1u});
    vkCmdUpdateBuffer(cmd, vkBuffer(gpu, s.dispatch), 0, args.size() * 4, args.data());
    vkCmdFillBuffer(cmd, vkBuffer(gpu, s.superfluous), 0, VK_WHOLE_SIZE, 0);
    vkCmdFillBuffer(cmd, vkBuffer(gpu, s.featureTiles), 0, VK_WHOLE_SIZE, 0);
    if (s.chunks) vkCmdFillBuffer(cmd, vkBuffer(gpu, s.chunkListCount), 0, VK_WHOLE_SIZE, 0);
    // Before the tile pass's atomics (vkCmdUpdateBuffer counts as a transfer: ALL_TRANSFER).
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
}

void recordTileShading(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    SpectraState& s = *r.spectra;
    // The tile pass wrote the bins and their dispatch sizes.
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
    imageBarrier(cmd, vkImage(gpu, r.hdr), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                 VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, 0,
                 VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    TileShadePush push{frame, visibilityBufferSlot(r), visibilityHdrWriteSlot(r)};
    for (size_t m = 0; m < s.modes.size(); ++m) {
        bind(gpu, cmd, s.shading[m]);
        pushConstants(gpu, cmd, push);
        vkCmdDispatchIndirect(cmd, vkBuffer(gpu, s.dispatch), VkDeviceSize(m) * 12);
    }
    // Blended surfaces (render/oit) are drawn over the result as colour attachments.
    imageBarrier(cmd, vkImage(gpu, r.hdr), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
                 VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                 VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                 VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT);
}

namespace {
struct ChunkSpectraSetupPush {
    uint64_t spectraFrame;
};
} // namespace

void recordChunkSpectraClassify(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    SpectraState& s = *r.spectra;
    ShadelShadingQueue queue = shadelShadingQueue(r);
    bind(gpu, cmd, s.classify);
    pushConstants(gpu, cmd, frame);
    vkCmdDispatchIndirect(cmd, vkBuffer(gpu, queue.counters), queue.invocationDispatchOffset);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    bind(gpu, cmd, s.setup);
    pushConstants(gpu, cmd, ChunkSpectraSetupPush{address(gpu, s.frame)});
    vkCmdDispatch(cmd, 1, 1, 1);
    // The bins and their dispatch sizes, for the long lists and the per-spectrum shading.
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
    // The lists classify left to their own pass (more lights than it keeps), before shading
    // reads them.
    bind(gpu, cmd, s.longLists);
    pushConstants(gpu, cmd, frame);
    vkCmdDispatchIndirect(cmd, vkBuffer(gpu, s.chunkListCount),
                          SPECTRA_LONG_LIST_DISPATCH * sizeof(uint32_t));
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
}

void recordChunkSpectraShading(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    SpectraState& s = *r.spectra;
    for (size_t m = 0; m < s.modes.size(); ++m) {
        bind(gpu, cmd, s.shading[m]);
        pushConstants(gpu, cmd, frame);
        vkCmdDispatchIndirect(cmd, vkBuffer(gpu, s.dispatch), VkDeviceSize(m) * 16);
    }
}

void readFeatureSpectraStats(Renderer& r) {
    if (!r.spectra) return;
    Gpu& gpu = *r.gpu;
    SpectraState& s = *r.spectra;
    size_t modes = s.modes.size();
    const uint32_t* args = static_cast<const uint32_t*>(mapped(gpu, s.dispatch));
    s.binned.resize(modes);
    for (size_t m = 0; m < modes; ++m) s.binned[m] = s.chunks ? args[m * 4 + 3] : args[m * 3];
    const uint32_t* sup = static_cast<const uint32_t*>(mapped(gpu, s.superfluous));
    s.lastSuperfluous.assign(sup, sup + modes * SPECTRUM_FEATURE_COUNT);
    const uint32_t* ft = static_cast<const uint32_t*>(mapped(gpu, s.featureTiles));
    s.lastFeatureTiles.assign(ft, ft + SPECTRUM_FEATURE_COUNT + SPECTRUM_ALL + 1);
    if (s.chunks) {
        const uint32_t* lists = static_cast<const uint32_t*>(mapped(gpu, s.chunkListCount));
        s.lastChunkListEntries = lists[0];
        s.lastChunksPoolOverflow = lists[1];
        s.lastChunksLongLists = lists[2];
    }
}

void featureSpectraStats(const Renderer& r, nlohmann::json& stats) {
    stats["spectra_mode"] = r.settings.spectra == Spectra::On       ? "on"
                            : r.settings.spectra == Spectra::Single ? "single"
                                                                    : "off";
    if (!r.spectra || r.spectra->binned.empty()) return;
    const SpectraState& s = *r.spectra;
    stats["spectra_unit"] = s.chunks ? "chunks" : "tiles"; // what "spectra" counts
    nlohmann::json spectra = nlohmann::json::object(), superfluous = nlohmann::json::object(),
                   features = nlohmann::json::object();
    uint64_t superfluousTotal = 0;
    for (size_t m = 0; m < s.modes.size(); ++m) {
        std::string name = modeName(s.modes[m]);
        spectra[name] = s.binned[m];
        nlohmann::json extra = nlohmann::json::object();
        for (uint32_t bit = 0; bit < SPECTRUM_FEATURE_COUNT; ++bit) {
            uint32_t n = s.lastSuperfluous[m * SPECTRUM_FEATURE_COUNT + bit];
            if (n) extra[kFeatureNames[bit]] = n;
            superfluousTotal += n;
        }
        superfluous[name] = extra;
    }
    for (uint32_t bit = 0; bit < SPECTRUM_FEATURE_COUNT; ++bit)
        features[kFeatureNames[bit]] = s.lastFeatureTiles[bit];
    // The most common exact feature sets (what the modes were chosen from).
    std::vector<std::pair<uint32_t, uint32_t>> sets;
    for (uint32_t set = 0; set <= SPECTRUM_ALL; ++set)
        if (uint32_t n = s.lastFeatureTiles[SPECTRUM_FEATURE_COUNT + set]) sets.push_back({n, set});
    std::sort(sets.rbegin(), sets.rend());
    nlohmann::json topSets = nlohmann::json::object();
    for (size_t i = 0; i < sets.size() && i < 12; ++i)
        topSets[modeName(sets[i].second)] = sets[i].first;
    stats["tile_feature_sets"] = topSets;       // the 12 most common, exact set -> tiles
    stats["spectra"] = spectra;                 // mode -> tiles
    stats["spectra_superfluous"] = superfluous; // mode -> feature -> tiles not needing it
    stats["spectra_superfluous_total"] = superfluousTotal; // (tile, feature) pairs
    stats["tile_features"] = features;                     // feature -> tiles needing it
    if (s.chunks) {
        // The classify pass's lists the permutations read (their kept lights' entries); the
        // chunks whose list did not fit the pool (their permutation takes every light, each
        // blocker per shadel: the same sum, slower; binned to every feature); the chunks with
        // more lights than classify keeps in its private list (written by two walks instead).
        stats["spectra_chunk_list_entries"] = s.lastChunkListEntries;
        stats["spectra_chunk_list_capacity"] = s.chunkListCapacity;
        stats["spectra_chunks_pool_overflow"] = s.lastChunksPoolOverflow;
        stats["spectra_chunks_long_lists"] = s.lastChunksLongLists;
    }
}

} // namespace shadel
