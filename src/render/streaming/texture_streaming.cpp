#include "render/streaming/texture_streaming.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <mutex>
#include <thread>

#include <fcntl.h>
#include <unistd.h>

#include "bake/texture_pack.h"
#include "core/error.h"
#include "core/log.h"
#include "render/streaming/sparse_textures.h"
#include "render/streaming/texture_priority.h"
#include "rhi/bindless.h"
#include "rhi/gpu.h"

namespace shadel {

namespace {

uint32_t log2u(uint32_t v) {
    uint32_t r = 0;
    while ((v >> r) > 1) ++r;
    return r;
}

// One cache image: a square image of the file's format (RGBA8 or BC7) with its full MIP chain,
// read through a linear or an sRGB view (the slot serves both kinds of texture, so one slot size
// serves both).
struct CacheImage {
    TextureHandle image;
    TextureReadView linear, srgb;
    uint32_t size = 0;
};

TextureDesc cacheImageDesc(const std::string& name, uint32_t size, BlockFormat format) {
    TextureDesc d;
    d.name = name;
    d.format = packedVkFormat(format, false);
    d.width = d.height = size;
    d.mipLevels = log2u(size) + 1;
    d.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
    d.flags = VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT;
    return d;
}

CacheImage makeCacheImage(Gpu& gpu, const std::string& name, uint32_t size, BlockFormat format) {
    CacheImage c;
    c.size = size;
    c.image = createTexture(gpu, cacheImageDesc(name, size, format));
    if (!c.image) throw DeviceError("out of GPU memory for texture cache image " + name);
    c.linear =
        createReadView(gpu, c.image, {0, VK_REMAINING_MIP_LEVELS, packedVkFormat(format, false)});
    c.srgb =
        createReadView(gpu, c.image, {0, VK_REMAINING_MIP_LEVELS, packedVkFormat(format, true)});
    return c;
}

void destroyCacheImage(Gpu& gpu, CacheImage& c) {
    destroy(gpu, c.linear);
    destroy(gpu, c.srgb);
    destroy(gpu, c.image);
    c = {};
}

// The copy regions of consecutive pack levels [firstLevel, endLevel), tiles as the file stores
// them, at bufferOffset in a buffer, into mips firstMip.. of an image (0 for a layered slot, whose
// mip 0 is the level it holds; firstLevel for a sparse image, which holds every level).
void appendLevelRegions(const PackedTexture& t, uint32_t firstLevel, uint32_t endLevel,
                        uint32_t firstMip, VkDeviceSize bufferOffset,
                        std::vector<VkBufferImageCopy>& regions) {
    const uint32_t unit = blockSide(t.format); // rows of whole blocks in the buffer
    for (uint32_t l = firstLevel; l < endLevel; ++l) {
        uint32_t side = t.levels[l].size;
        uint32_t tile = std::min(side, kTexturePackTile);
        uint32_t rowTexels = (tile + unit - 1) / unit * unit;
        VkDeviceSize o = bufferOffset;
        for (uint32_t ty = 0; ty < side; ty += tile)
            for (uint32_t tx = 0; tx < side; tx += tile) {
                VkBufferImageCopy r{};
                r.bufferOffset = o;
                r.bufferRowLength = rowTexels;
                r.bufferImageHeight = rowTexels;
                r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, l - firstLevel + firstMip, 0, 1};
                r.imageOffset = {int32_t(tx), int32_t(ty), 0};
                r.imageExtent = {tile, tile, 1};
                regions.push_back(r);
                o += encodedBytes(t.format, tile, tile);
            }
        bufferOffset += t.levels[l].bytes;
    }
}

uint64_t levelBytesFrom(const PackedTexture& t, uint32_t firstLevel, uint32_t endLevel = ~0u) {
    uint64_t bytes = 0;
    endLevel = std::min<uint32_t>(endLevel, uint32_t(t.levels.size()));
    for (uint32_t l = firstLevel; l < endLevel; ++l) bytes += t.levels[l].bytes;
    return bytes;
}

// A load of an exchange's levels (layered) or of the levels down to a target (sparse) from the file
// into the staging ring.
struct LoadJob {
    CacheExchange exchange;  // exchange.texture: the texture read (both modes)
    SparseLevelLoad sparse;  // sparse: the levels and the pages they are bound to
    uint32_t firstLevel = 0; // layered: the pack level that becomes the slot's mip 0
    uint32_t endLevel = 0;   // pack levels [firstLevel, endLevel) are read
    uint64_t stagingOffset = 0, bytes = 0;
    std::atomic<int> state{0}; // 0 queued, 1 loaded, 2 failed
    std::string error;
};

// First-in first-out allocations in one host-visible buffer (loads land in the order they were
// queued: one worker), freed from the front after the frame that copied them.
struct StagingRing {
    uint64_t capacity = 0;
    std::deque<std::pair<uint64_t, uint64_t>> live; // offset, bytes
    bool allocate(uint64_t bytes, uint64_t& offset) {
        bytes = (bytes + 15) & ~uint64_t(15);
        if (bytes > capacity) return false;
        if (live.empty()) {
            offset = 0;
        } else {
            uint64_t front = live.front().first;
            uint64_t end = live.back().first + live.back().second;
            if (live.back().first >= front) { // not wrapped
                if (end + bytes <= capacity)
                    offset = end;
                else if (bytes <= front)
                    offset = 0;
                else
                    return false;
            } else if (end + bytes <= front) {
                offset = end;
            } else {
                return false;
            }
        }
        live.push_back({offset, bytes});
        return true;
    }
    void releaseFront() { live.pop_front(); }
    uint64_t used() const {
        uint64_t n = 0;
        for (auto& a : live) n += a.second;
        return n;
    }
};

} // namespace

struct TextureStreaming {
    Gpu* gpu = nullptr;
    TextureStreamingSettings settings;
    TexturePack pack;
    int fd = -1;
    BlockFormat format = BlockFormat::Rgba8; // every texture's in the file and the caches
    std::string compressionFallback;         // why BC was asked for but the file is RGBA8
    bool resident = false;                   // no budget: every texture whole
    TextureCache cache;
    std::vector<CacheImage> tails;              // per texture (resident: the whole texture)
    std::vector<std::vector<CacheImage>> slots; // per layer, per slot
    std::vector<BindlessSlot> logical;          // per texture, persistent
    std::vector<uint32_t> logicalSlots;
    uint64_t imageBytes = 0; // what the cache images take (budget-checked)
    bool sparseMode = false; // --streaming sparse with a budget: `sparse` instead of tails+slots
    SparseTextures sparse;
    VkSemaphore bindWait = VK_NULL_HANDLE; // this frame's sparse binds, for the frame to wait on

    // Priorities.
    std::vector<TextureUse> uses;
    std::vector<std::vector<uint32_t>> materialsOf; // per texture: the materials sampling it
    std::vector<uint8_t> restreamed;                // per material, this frame
    std::vector<float> gpuWanted;
    std::vector<uint64_t> gpuSeenFrame;
    BufferHandle feedback; // uint per bindless sampled slot
    uint64_t frame = 0;

    // Loads.
    BufferHandle staging;
    StagingRing ring;
    std::deque<std::unique_ptr<LoadJob>> jobs;    // queued or loaded, in queue order
    std::vector<std::unique_ptr<LoadJob>> landed; // committed this frame, copied by the pass
    std::mutex mutex;
    std::condition_variable wake;
    std::deque<LoadJob*> queue;
    bool stopping = false;
    std::thread worker;

    // Statistics.
    uint64_t exchangesStarted = 0, exchangesCommitted = 0, loadsFailed = 0, bytesLoaded = 0;
    std::vector<uint64_t> residentPerFrame, exchangesPerFrame;
    std::vector<uint32_t> pendingPerFrame;
    std::vector<uint32_t> sparsePagesPerFrame; // resident pages after each frame
    uint32_t sparsePagesPeak = 0;              // used pages (resident + reserved), peak
    uint64_t sparseEvictions = 0;
    double prepareMsTotal = 0.0;
};

static void workerLoop(TextureStreaming* s) {
    uint8_t* base = static_cast<uint8_t*>(mapped(*s->gpu, s->staging));
    for (;;) {
        LoadJob* job = nullptr;
        {
            std::unique_lock<std::mutex> lock(s->mutex);
            s->wake.wait(lock, [&] { return s->stopping || !s->queue.empty(); });
            if (s->stopping) return;
            job = s->queue.front();
            s->queue.pop_front();
        }
        const PackedTexture& t = s->pack.textures[job->exchange.texture];
        uint64_t o = job->stagingOffset;
        bool ok = true;
        for (uint32_t l = job->firstLevel; l < job->endLevel && ok; ++l) {
            ok = readPackedLevel(s->fd, t.levels[l], base + o, &job->error);
            o += t.levels[l].bytes;
        }
        job->state.store(ok ? 1 : 2, std::memory_order_release);
    }
}

void TextureStreamingDeleter::operator()(TextureStreaming* s) const {
    if (!s) return;
    {
        std::lock_guard<std::mutex> lock(s->mutex);
        s->stopping = true;
    }
    s->wake.notify_all();
    if (s->worker.joinable()) s->worker.join();
    Gpu& gpu = *s->gpu;
    vkDeviceWaitIdle(gpu.device.device);
    for (BindlessSlot b : s->logical) freeBindless(gpu, BindlessKind::Sampled, b);
    for (CacheImage& c : s->tails) destroyCacheImage(gpu, c);
    for (auto& layer : s->slots)
        for (CacheImage& c : layer) destroyCacheImage(gpu, c);
    destroySparseTextures(s->sparse);
    destroy(gpu, s->feedback);
    destroy(gpu, s->staging);
    if (s->fd >= 0) ::close(s->fd);
    delete s;
}

static uint64_t deviceImageBytes(Gpu& gpu, uint32_t size, BlockFormat format) {
    TextureDesc d = cacheImageDesc("probe", size, format);
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.flags = d.flags;
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = d.format;
    ci.extent = {size, size, 1};
    ci.mipLevels = d.mipLevels;
    ci.arrayLayers = 1;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.tiling = VK_IMAGE_TILING_OPTIMAL;
    ci.usage = d.usage | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    VkDeviceImageMemoryRequirements info{VK_STRUCTURE_TYPE_DEVICE_IMAGE_MEMORY_REQUIREMENTS};
    info.pCreateInfo = &ci;
    VkMemoryRequirements2 req{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2};
    vkGetDeviceImageMemoryRequirements(gpu.device.device, &info, &req);
    VkDeviceSize align = std::max<VkDeviceSize>(req.memoryRequirements.alignment, 1);
    return (req.memoryRequirements.size + align - 1) / align * align;
}

// Uploads pack levels [firstLevel, end) of each listed texture into its image from mip firstMip
// on (0: a cache image; firstLevel: a sparse image's tail), synchronously (creation only: the
// tails, or every texture whole without a budget), a few at a time.
struct InitialUpload {
    VkImage image = VK_NULL_HANDLE;
    uint32_t firstMip = 0;
};
static void uploadWhole(TextureStreaming& s,
                        const std::vector<std::pair<uint32_t, uint32_t>>& items,
                        const std::vector<InitialUpload>& images) {
    Gpu& gpu = *s.gpu;
    const uint64_t batchLimit = 256ull << 20;
    size_t i = 0;
    while (i < items.size()) {
        size_t end = i;
        uint64_t bytes = 0;
        while (end < items.size() &&
               (end == i ||
                bytes + levelBytesFrom(s.pack.textures[items[end].first], items[end].second) <=
                    batchLimit))
            bytes += levelBytesFrom(s.pack.textures[items[end].first], items[end].second), ++end;
        BufferHandle staging =
            createBuffer(gpu, {"streaming.initialUpload", bytes, 0, MemoryKind::Upload});
        if (!staging) throw DeviceError("out of host-visible memory uploading streamed textures");
        uint8_t* base = static_cast<uint8_t*>(mapped(gpu, staging));
        uint64_t o = 0;
        std::vector<uint64_t> offsets;
        for (size_t k = i; k < end; ++k) {
            const PackedTexture& t = s.pack.textures[items[k].first];
            offsets.push_back(o);
            for (uint32_t l = items[k].second; l < t.levels.size(); ++l) {
                std::string why;
                if (!readPackedLevel(s.fd, t.levels[l], base + o, &why))
                    throw std::runtime_error(s.pack.path + ": texture " +
                                             std::to_string(items[k].first) + ": " + why +
                                             " (the file changed while in use?)");
                o += t.levels[l].bytes;
            }
        }
        immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
            for (size_t k = i; k < end; ++k) {
                VkImage image = images[k].image;
                uint32_t mip = images[k].firstMip;
                imageBarrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                             VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
                             VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, mip);
                const PackedTexture& t = s.pack.textures[items[k].first];
                std::vector<VkBufferImageCopy> regions;
                appendLevelRegions(t, items[k].second, uint32_t(t.levels.size()), mip,
                                   offsets[k - i], regions);
                vkCmdCopyBufferToImage(cmd, vkBuffer(gpu, staging), image,
                                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                       uint32_t(regions.size()), regions.data());
                imageBarrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT,
                             VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                             VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
                             VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                             VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, mip);
            }
        });
        destroy(gpu, staging);
        i = end;
    }
}

static VkImageView viewFor(const TextureStreaming& s, const CacheImage& c, uint32_t texture) {
    return sampledImageView(*s.gpu, s.pack.textures[texture].srgb ? c.srgb : c.linear);
}

TextureStreamingPtr createTextureStreaming(Gpu& gpu, const Scene& scene,
                                           const TextureStreamingSettings& settings,
                                           const std::string& cacheDir) {
    if (settings.mode == StreamingMode::Sparse) {
        std::string why = sparseUnsupportedReason(gpu, BlockFormat::Rgba8);
        if (!why.empty()) throw InputError("--streaming sparse: " + why);
    }
    TextureStreamingPtr sp(new TextureStreaming);
    TextureStreaming& s = *sp;
    s.gpu = &gpu;
    s.settings = settings;
    s.resident = !(settings.budgetMiB > 0.0);
    TextureCompression compression = settings.compression;
    if (compression == TextureCompression::Bc) {
        if (!gpu.device.optional.textureCompressionBC)
            s.compressionFallback =
                gpu.device.name + " cannot sample block-compressed textures (textureCompressionBC)";
        else if (!s.resident && settings.mode == StreamingMode::Sparse)
            s.compressionFallback = sparseUnsupportedReason(gpu, BlockFormat::Bc7);
        if (!s.compressionFallback.empty()) {
            SHADEL_WARN("--texture-compression bc: %s: textures stream as RGBA8",
                        s.compressionFallback.c_str());
            compression = TextureCompression::None;
        }
    }
    s.pack = openOrBuildTexturePack(scene, cacheDir, compression);
    s.fd = s.pack.fd; // closed with the streaming state
    if (!s.pack.textures.empty()) s.format = s.pack.textures[0].format;
    for (const PackedTexture& t : s.pack.textures)
        if (t.format != s.format)
            throw std::runtime_error(s.pack.path + ": textures of different block formats");
    const size_t n = s.pack.textures.size();
    std::vector<uint32_t> sizes;
    for (const PackedTexture& t : s.pack.textures) sizes.push_back(t.size);

    uint64_t budget = uint64_t(settings.budgetMiB * 1048576.0);
    s.sparseMode = !s.resident && settings.mode == StreamingMode::Sparse;

    // Images: the tails (or, resident, every texture whole; or the sparse images, tails bound).
    std::vector<std::pair<uint32_t, uint32_t>> items;
    std::vector<InitialUpload> targets;
    if (s.sparseMode) {
        std::vector<bool> srgb;
        for (const PackedTexture& t : s.pack.textures) srgb.push_back(t.srgb);
        createSparseTextures(gpu, sizes, srgb, s.format, budget, s.sparse);
        for (uint32_t i = 0; i < n; ++i) {
            uint32_t tailFirst = s.sparse.residency.textures[i].tailFirst;
            items.push_back({i, tailFirst});
            targets.push_back({s.sparse.images[i].image, tailFirst});
        }
        s.imageBytes = s.sparse.tailBytes + s.sparse.poolBytes; // allocated once, never grown
    } else {
        for (uint32_t i = 0; i < n; ++i) {
            uint32_t side = s.resident ? sizes[i] : std::min(sizes[i], kTailSize);
            s.tails.push_back(
                makeCacheImage(gpu, format("streaming.%s.%u", s.resident ? "texture" : "tail", i),
                               side, s.format));
            items.push_back({i, log2u(sizes[i]) - log2u(side)});
            targets.push_back({vkImage(gpu, s.tails.back().image), 0});
            s.imageBytes += deviceImageBytes(gpu, side, s.format);
        }
    }
    if (!s.resident && !s.sparseMode) {
        s.cache = makeTextureCache(
            sizes, budget, [&](uint32_t side) { return deviceImageBytes(gpu, side, s.format); });
        for (size_t k = 0; k < s.cache.layers.size(); ++k) {
            s.slots.emplace_back();
            for (size_t j = 0; j < s.cache.layers[k].owner.size(); ++j) {
                s.slots[k].push_back(makeCacheImage(
                    gpu, format("streaming.layer%u.slot%zu", s.cache.layers[k].size, j),
                    s.cache.layers[k].size, s.format));
                s.imageBytes += deviceImageBytes(gpu, s.cache.layers[k].size, s.format);
            }
        }
        immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
            for (auto& layer : s.slots)
                for (CacheImage& c : layer)
                    imageBarrier(cmd, vkImage(gpu, c.image), VK_IMAGE_ASPECT_COLOR_BIT,
                                 VK_IMAGE_LAYOUT_UNDEFINED,
                                 VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_NONE,
                                 0, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                 VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
        });
    }
    if (!s.resident) {
        s.feedback =
            createBuffer(gpu, {"streaming.feedback", kBindlessSampledCapacity * sizeof(uint32_t),
                               VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryKind::Readback});
        s.staging = createBuffer(gpu, {"streaming.stagingRing", uint64_t(settings.stagingMiB) << 20,
                                       0, MemoryKind::Upload});
        if (!s.feedback || !s.staging)
            throw DeviceError("out of memory for texture streaming buffers");
        std::memset(mapped(gpu, s.feedback), 0xff, kBindlessSampledCapacity * sizeof(uint32_t));
        s.ring.capacity = uint64_t(settings.stagingMiB) << 20;
        s.uses = textureUses(scene);
        s.materialsOf.resize(n);
        for (uint32_t m = 0; m < scene.materials.size(); ++m) {
            const Material& mat = scene.materials[m];
            for (int32_t t :
                 {mat.baseColorTexture, mat.metallicRoughnessTexture, mat.normalTexture,
                  mat.emissiveTexture, mat.occlusionTexture, mat.clearcoatTexture,
                  mat.clearcoatRoughnessTexture, mat.clearcoatNormalTexture, mat.specularTexture,
                  mat.specularColorTexture, mat.sheenColorTexture, mat.sheenRoughnessTexture,
                  mat.transmissionTexture, mat.thicknessTexture})
                if (t >= 0 && size_t(t) < n) s.materialsOf[t].push_back(m);
        }
        s.restreamed.assign(scene.materials.size(), 0);
        s.gpuWanted.assign(n, 0.0f);
        s.gpuSeenFrame.assign(n, 0);
        s.worker = std::thread(workerLoop, &s);
    }
    uploadWhole(s, items, targets);
    for (uint32_t i = 0; i < n; ++i) {
        VkImageView view =
            s.sparseMode ? sparseResidentView(s.sparse, i) : viewFor(s, s.tails[i], i);
        s.logical.push_back(allocateBindless(gpu, BindlessKind::Sampled, view,
                                             VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL));
        s.logicalSlots.push_back(s.logical.back().value);
    }
    SHADEL_INFO("texture streaming: %zu textures (%s), %s, %.1f MiB of cache images", n,
                blockFormatName(s.format),
                s.resident     ? "all resident (no budget)"
                : s.sparseMode ? "sparse residency"
                               : "layered cache",
                double(s.imageBytes) / 1048576.0);
    return sp;
}

const std::vector<uint32_t>& streamedTextureSlots(const TextureStreaming& s) {
    return s.logicalSlots;
}

const std::vector<uint8_t>& restreamedMaterials(const TextureStreaming& s) {
    return s.restreamed;
}

static void markRestreamed(TextureStreaming& s, int32_t texture) {
    if (texture >= 0)
        for (uint32_t m : s.materialsOf[texture]) s.restreamed[m] = 1;
}

// Hands a load to the worker thread: its bytes land at `offset` in the staging ring.
static void startLoad(TextureStreaming& s, std::unique_ptr<LoadJob> job, uint64_t offset,
                      uint64_t bytes) {
    job->stagingOffset = offset;
    job->bytes = bytes;
    {
        std::lock_guard<std::mutex> lock(s.mutex);
        s.queue.push_back(job.get());
    }
    s.jobs.push_back(std::move(job));
}

// Sparse residency's frame (priorities already merged): landed level loads bound (their copies
// are the pass's), new loads planned with the evictions that make room, all binds queued for the
// frame to wait on; every texture whose level changed sampled through its new view.
static void prepareSparseFrame(TextureStreaming& s) {
    Gpu& gpu = *s.gpu;
    SparseResidency& res = s.sparse.residency;
    beginSparseFrame(res);
    std::vector<const SparseLevelLoad*> binds;
    auto rebind = [&](int32_t t) {
        updateBindless(gpu, BindlessKind::Sampled, s.logical[t], sparseResidentView(s.sparse, t),
                       VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        markRestreamed(s, t);
    };
    while (!s.jobs.empty()) {
        int state = s.jobs.front()->state.load(std::memory_order_acquire);
        if (state == 0) break;
        std::unique_ptr<LoadJob> job = std::move(s.jobs.front());
        s.jobs.pop_front();
        if (state == 2) {
            SHADEL_WARN("texture streaming: texture %d levels %u.. load failed (%s); it stays at "
                        "its level",
                        job->sparse.texture, job->sparse.level, job->error.c_str());
            abandonSparseLoad(res, job->sparse);
            s.loadsFailed++;
        } else {
            commitSparseLoad(res, job->sparse);
            binds.push_back(&job->sparse);
            rebind(job->sparse.texture);
            s.exchangesCommitted++;
            s.bytesLoaded += job->bytes;
        }
        s.landed.push_back(std::move(job)); // copied by the pass; staging freed in order
    }

    std::vector<SparseLevelLoad> planned;
    std::vector<SparseEviction> evictions;
    // Loads land in the staging ring: none larger than its free space (a page holds as many bytes
    // as the file's tiles of its texels), so a load is rarely planned (and room made) for nothing.
    uint64_t ringFree = s.ring.capacity - s.ring.used();
    planSparseLoads(res, s.settings.limits, ringFree / s.sparse.pageBytes, planned, evictions);
    for (const SparseEviction& e : evictions) rebind(e.texture);
    s.sparseEvictions += evictions.size();
    size_t started = 0;
    for (SparseLevelLoad& load : planned) {
        const PackedTexture& t = s.pack.textures[load.texture];
        uint64_t bytes = levelBytesFrom(t, load.level, load.level + load.levels), offset = 0;
        if (!s.ring.allocate(bytes, offset)) {
            abandonSparseLoad(res, load);
            res.textures[load.texture].failedLoads--; // not the load's fault: retried later
            continue;
        }
        auto job = std::make_unique<LoadJob>();
        job->exchange.texture = load.texture;
        job->firstLevel = load.level;
        job->endLevel = load.level + load.levels;
        job->sparse = std::move(load);
        startLoad(s, std::move(job), offset, bytes);
        ++started;
    }
    if (started) s.wake.notify_one();
    s.exchangesStarted += started;
    s.bindWait = submitSparseBinds(s.sparse, binds, evictions);
}

VkSemaphore takeTextureStreamingWait(TextureStreaming& s) {
    VkSemaphore sem = s.bindWait;
    s.bindWait = VK_NULL_HANDLE;
    return sem;
}

void prepareTextureStreaming(TextureStreaming& s, const CameraView& camera, float viewportHeight,
                             gpu::FrameConstants& constants) {
    if (s.resident) return;
    Gpu& gpu = *s.gpu;
    const size_t n = s.pack.textures.size();
    // GPU wishes from the last frame (the buffer is read before this frame's pass clears it).
    const uint32_t* fb = static_cast<const uint32_t*>(mapped(gpu, s.feedback));
    for (size_t t = 0; t < n; ++t) {
        uint32_t mip = fb[s.logicalSlots[t]];
        if (mip <= 15) {
            s.gpuWanted[t] = float(32768u >> mip);
            s.gpuSeenFrame[t] = s.frame;
        } else if (s.frame > s.gpuSeenFrame[t] + s.settings.feedbackFrames) {
            s.gpuWanted[t] = 0.0f; // not sampled lately
        }
    }
    std::vector<float> cpu = cpuWantedSizes(s.uses, n, camera, viewportHeight);
    for (size_t t = 0; t < n; ++t) {
        float wanted = mergedWanted(cpu[t], s.gpuWanted[t], s.settings.cpuCap);
        (s.sparseMode ? s.sparse.residency.textures[t].wanted : s.cache.textures[t].wanted) =
            wanted;
    }
    std::fill(s.restreamed.begin(), s.restreamed.end(), 0);
    constants.textureFeedback = address(gpu, s.feedback);
    if (s.sparseMode) {
        prepareSparseFrame(s);
        return;
    }

    // Landed loads, in queue order: commit (ownership, bindless) and leave the copies to the pass.
    while (!s.jobs.empty()) {
        int state = s.jobs.front()->state.load(std::memory_order_acquire);
        if (state == 0) break;
        std::unique_ptr<LoadJob> job = std::move(s.jobs.front());
        s.jobs.pop_front();
        const CacheExchange& e = job->exchange;
        if (state == 2) {
            SHADEL_WARN("texture streaming: texture %d load failed (%s); it stays at its level",
                        e.texture, job->error.c_str());
            abandonExchange(s.cache, e);
            s.loadsFailed++;
            s.landed.push_back(std::move(job)); // nothing to copy; its staging goes in order
            continue;
        }
        commitExchange(s.cache, e);
        for (int32_t t : {e.texture, e.victim})
            if (t >= 0)
                for (uint32_t m : s.materialsOf[t]) s.restreamed[m] = 1;
        updateBindless(gpu, BindlessKind::Sampled, s.logical[e.texture],
                       viewFor(s, s.slots[e.toLayer][e.toSlot], e.texture),
                       VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        if (e.victim >= 0)
            updateBindless(
                gpu, BindlessKind::Sampled, s.logical[e.victim],
                viewFor(s, e.fromLayer >= 0 ? s.slots[e.fromLayer][e.fromSlot] : s.tails[e.victim],
                        e.victim),
                VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        s.exchangesCommitted++;
        s.bytesLoaded += job->bytes;
        s.landed.push_back(std::move(job));
    }

    // New exchanges: a load each, while the staging ring has room.
    std::vector<CacheExchange> planned = planExchanges(s.cache, s.settings.limits);
    size_t started = 0;
    for (const CacheExchange& e : planned) {
        const PackedTexture& t = s.pack.textures[e.texture];
        uint32_t first = log2u(t.size) - log2u(s.cache.layers[e.toLayer].size);
        uint64_t bytes = levelBytesFrom(t, first), offset = 0;
        if (!s.ring.allocate(bytes, offset)) {
            abandonExchange(s.cache, e);
            s.cache.textures[e.texture].failedLoads--; // not the load's fault: retried later
            continue;
        }
        auto job = std::make_unique<LoadJob>();
        job->exchange = e;
        job->firstLevel = first;
        job->endLevel = uint32_t(t.levels.size());
        startLoad(s, std::move(job), offset, bytes);
        ++started;
    }
    if (started) s.wake.notify_one();
    s.exchangesStarted += started;
}

void recordTextureStreaming(TextureStreaming& s, VkCommandBuffer cmd) {
    if (s.resident) return;
    Gpu& gpu = *s.gpu;
    vkCmdFillBuffer(cmd, vkBuffer(gpu, s.feedback), 0, VK_WHOLE_SIZE, 0xFFFFFFFFu);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    const VkImageLayout ro = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    const VkPipelineStageFlags2 shaders = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    if (s.sparseMode) { // each landed level into its freshly bound pages (the frame waited on them)
        for (const auto& job : s.landed) {
            if (job->state.load(std::memory_order_acquire) != 1) continue;
            const SparseLevelLoad& l = job->sparse;
            VkImage image = s.sparse.images[l.texture].image;
            imageBarrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
                         VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, l.level,
                         l.levels);
            std::vector<VkBufferImageCopy> regions;
            appendLevelRegions(s.pack.textures[l.texture], l.level, l.level + l.levels, l.level,
                               job->stagingOffset, regions);
            vkCmdCopyBufferToImage(cmd, vkBuffer(gpu, s.staging), image,
                                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, uint32_t(regions.size()),
                                   regions.data());
            imageBarrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT,
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, ro, VK_PIPELINE_STAGE_2_COPY_BIT,
                         VK_ACCESS_2_TRANSFER_WRITE_BIT, shaders,
                         VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, l.level, l.levels);
        }
        return;
    }
    for (const auto& job : s.landed) {
        if (job->state.load(std::memory_order_acquire) != 1) continue; // failed: nothing landed
        const CacheExchange& e = job->exchange;
        const PackedTexture& t = s.pack.textures[e.texture];
        VkImage up = vkImage(gpu, s.slots[e.toLayer][e.toSlot].image);
        bool moveDown = e.victim >= 0 && e.fromLayer >= 0;
        // The yielding texture's lower levels move into the slot the upgraded texture leaves.
        if (moveDown) {
            VkImage down = vkImage(gpu, s.slots[e.fromLayer][e.fromSlot].image);
            imageBarrier(cmd, up, VK_IMAGE_ASPECT_COLOR_BIT, ro,
                         VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, shaders,
                         VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                         VK_ACCESS_2_TRANSFER_READ_BIT);
            imageBarrier(cmd, down, VK_IMAGE_ASPECT_COLOR_BIT, ro,
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, shaders,
                         VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                         VK_ACCESS_2_TRANSFER_WRITE_BIT);
            uint32_t skip = uint32_t(e.toLayer - e.fromLayer);
            uint32_t levels = log2u(s.cache.layers[e.fromLayer].size) + 1;
            std::vector<VkImageCopy> copies;
            for (uint32_t m = 0; m < levels; ++m) {
                uint32_t side = s.cache.layers[e.fromLayer].size >> m;
                VkImageCopy c{};
                c.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m + skip, 0, 1};
                c.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m, 0, 1};
                c.extent = {side, side, 1};
                copies.push_back(c);
            }
            vkCmdCopyImage(cmd, up, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, down,
                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, uint32_t(copies.size()),
                           copies.data());
            imageBarrier(cmd, down, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         ro, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, shaders,
                         VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
            imageBarrier(cmd, up, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
                         VK_ACCESS_2_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                         VK_ACCESS_2_TRANSFER_WRITE_BIT);
        } else {
            imageBarrier(cmd, up, VK_IMAGE_ASPECT_COLOR_BIT, ro,
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, shaders,
                         VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                         VK_ACCESS_2_TRANSFER_WRITE_BIT);
        }
        std::vector<VkBufferImageCopy> regions;
        appendLevelRegions(t, job->firstLevel, job->endLevel, 0, job->stagingOffset, regions);
        vkCmdCopyBufferToImage(cmd, vkBuffer(gpu, s.staging), up,
                               VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, uint32_t(regions.size()),
                               regions.data());
        imageBarrier(cmd, up, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, ro,
                     VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, shaders,
                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
    }
}

void finishTextureStreamingFrame(TextureStreaming& s) {
    if (s.resident) return;
    for (size_t i = 0; i < s.landed.size(); ++i) s.ring.releaseFront();
    uint64_t copied = 0;
    for (const auto& job : s.landed) copied += job->state.load(std::memory_order_acquire) == 1;
    s.exchangesPerFrame.push_back(copied);
    s.landed.clear();
    if (s.sparseMode) {
        uint32_t pages = residentPages(s.sparse.residency);
        s.sparsePagesPerFrame.push_back(pages);
        s.sparsePagesPeak = std::max(s.sparsePagesPeak, usedPages(s.sparse.residency));
        s.residentPerFrame.push_back(s.sparse.tailBytes + uint64_t(pages) * s.sparse.pageBytes);
    } else {
        s.residentPerFrame.push_back(residentBytes(s.cache));
    }
    s.pendingPerFrame.push_back(s.sparseMode ? s.sparse.residency.pending : s.cache.pending);
    s.frame++;
}

uint64_t textureMemoryPeakBytes(const TextureStreaming& s) {
    return s.imageBytes; // allocated once at creation, never grown
}

void textureStreamingStats(const TextureStreaming& s, nlohmann::json& stats) {
    stats["texture_memory_peak_bytes"] = textureMemoryPeakBytes(s);
    uint64_t totalBytes = 0, texels = 0;
    nlohmann::json formats = nlohmann::json::array(), psnr = nlohmann::json::array();
    for (const PackedTexture& t : s.pack.textures) {
        for (const PackedLevel& l : t.levels) {
            totalBytes += l.bytes;
            texels += uint64_t(l.size) * l.size;
        }
        formats.push_back(blockFormatName(t.format));
        psnr.push_back(std::round(double(t.psnr) * 100.0) / 100.0);
    }
    stats["texture_total_bytes"] = totalBytes;
    stats["texture_bytes_per_texel"] = texels ? double(totalBytes) / double(texels) : 0.0;
    nlohmann::json j;
    j["mode"] = s.resident ? "resident" : s.sparseMode ? "sparse" : "layered";
    j["textures"] = s.pack.textures.size();
    j["file"] = s.pack.path;
    j["file_bytes"] = s.pack.fileSize;
    j["compression"] = blockFormatName(s.format);
    if (!s.compressionFallback.empty()) j["compression_fallback"] = s.compressionFallback;
    j["formats"] = formats;
    j["psnr_db"] = psnr; // level 0 against its RGBA8 texels, 99 when identical
    j["encode_seconds"] = s.pack.encodeSeconds; // 0: the file came from the cache
    j["budget_bytes"] = s.resident ? 0 : uint64_t(s.settings.budgetMiB * 1048576.0);
    j["cache_image_bytes"] = s.imageBytes;
    if (s.sparseMode) {
        const SparseResidency& res = s.sparse.residency;
        j["tail_bytes"] = s.sparse.tailBytes;
        j["staging_ring_bytes"] = s.ring.capacity;
        j["exchanges_started"] = s.exchangesStarted; // level loads
        j["exchanges_committed"] = s.exchangesCommitted;
        j["loads_failed"] = s.loadsFailed;
        j["bytes_loaded"] = s.bytesLoaded;
        j["resident_bytes_per_frame"] = s.residentPerFrame;
        j["pending_per_frame"] = s.pendingPerFrame;
        j["exchanges_per_frame"] = s.exchangesPerFrame;
        nlohmann::json sp;
        sp["page_bytes"] = s.sparse.pageBytes;
        sp["page_texels"] = {s.sparse.granularity.width, s.sparse.granularity.height};
        sp["pool_pages"] = res.poolPages;
        sp["pool_bytes"] = s.sparse.poolBytes;
        sp["pages_resident"] = residentPages(res); // bound to whole resident levels now
        sp["pages_used_peak"] = s.sparsePagesPeak; // resident or reserved for loads in flight
        sp["pages_resident_per_frame"] = s.sparsePagesPerFrame;
        sp["page_binds"] = s.sparse.pageBinds;
        sp["page_unbinds"] = s.sparse.pageUnbinds;
        sp["level_evictions"] = s.sparseEvictions;
        j["sparse"] = sp;
        nlohmann::json sizes = nlohmann::json::array(), levels = nlohmann::json::array();
        for (const SparseTexture& t : res.textures) {
            sizes.push_back(t.size >> t.resident);
            levels.push_back(t.resident);
        }
        j["resident_sizes"] = sizes;
        j["resident_levels"] = levels;
    } else if (!s.resident) {
        nlohmann::json layers = nlohmann::json::array();
        for (const CacheLayer& l : s.cache.layers) {
            uint32_t used = 0;
            for (int32_t o : l.owner) used += o >= 0;
            layers.push_back({{"size", l.size},
                              {"slots", l.owner.size()},
                              {"used", used},
                              {"slot_bytes", l.slotBytes}});
        }
        j["layers"] = layers;
        j["tail_bytes"] = s.cache.tailBytes;
        j["staging_ring_bytes"] = s.ring.capacity;
        j["exchanges_started"] = s.exchangesStarted;
        j["exchanges_committed"] = s.exchangesCommitted;
        j["loads_failed"] = s.loadsFailed;
        j["bytes_loaded"] = s.bytesLoaded;
        j["resident_bytes_per_frame"] = s.residentPerFrame;
        j["exchanges_per_frame"] = s.exchangesPerFrame;
        j["pending_per_frame"] = s.pendingPerFrame;
        nlohmann::json sizes = nlohmann::json::array();
        for (const CachedTexture& t : s.cache.textures) sizes.push_back(residentSize(s.cache, t));
        j["resident_sizes"] = sizes;
    }
    stats["texture_streaming"] = j;
}

} // namespace shadel
