#include "render/streaming/sparse_textures.h"

#include <algorithm>

#include "core/assert.h"
#include "core/error.h"
#include "core/log.h"
#include "rhi/gpu.h"

namespace shadel {

namespace {

uint32_t log2u(uint32_t v) {
    uint32_t r = 0;
    while ((v >> r) > 1) ++r;
    return r;
}

constexpr VkImageUsageFlags kUsage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;

uint64_t alignUp(uint64_t v, uint64_t a) {
    return (v + a - 1) / a * a;
}

// The colour aspect's sparse layout of one image (granularity, where the tail starts and lies).
struct SparseLayout {
    VkSparseImageMemoryRequirements color{};
    std::vector<VkSparseImageMemoryRequirements> metadata; // aspects that must be bound whole
};

SparseLayout sparseLayout(VkDevice device, VkImage image) {
    uint32_t n = 0;
    vkGetImageSparseMemoryRequirements(device, image, &n, nullptr);
    std::vector<VkSparseImageMemoryRequirements> reqs(n);
    vkGetImageSparseMemoryRequirements(device, image, &n, reqs.data());
    SparseLayout out;
    bool color = false;
    for (const auto& r : reqs) {
        if (r.formatProperties.aspectMask & VK_IMAGE_ASPECT_COLOR_BIT)
            out.color = r, color = true;
        else if (r.formatProperties.aspectMask & VK_IMAGE_ASPECT_METADATA_BIT)
            out.metadata.push_back(r);
    }
    if (!color) throw DeviceError("sparse texture image without colour-aspect requirements");
    return out;
}

uint32_t blocksAcross(uint32_t side, uint32_t block) {
    return (side + block - 1) / block;
}

// What creating the images finds out, for the checks and the binds after.
struct SparseImagesMade {
    std::vector<SparseLayout> layouts;
    std::vector<SparseTexture> book; // per texture: its paged levels
    uint32_t memoryTypeBits = ~0u;
    uint64_t addressSpace = 0;
};

// One sparse image per texture, named; the page size and granularity, each texture's always-
// resident tail and its size.
SparseImagesMade createSparseImages(Gpu& gpu, const std::vector<uint32_t>& sizes,
                                    const std::vector<bool>& srgb, SparseTextures& out) {
    VkDevice device = gpu.device.device;
    SparseImagesMade made;
    for (size_t i = 0; i < sizes.size(); ++i) {
        SparseImage img;
        img.levels = log2u(sizes[i]) + 1;
        VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
        ci.flags = VK_IMAGE_CREATE_SPARSE_BINDING_BIT | VK_IMAGE_CREATE_SPARSE_RESIDENCY_BIT;
        ci.imageType = VK_IMAGE_TYPE_2D;
        ci.format = packedVkFormat(out.format, srgb[i]);
        ci.extent = {sizes[i], sizes[i], 1};
        ci.mipLevels = img.levels;
        ci.arrayLayers = 1;
        ci.samples = VK_SAMPLE_COUNT_1_BIT;
        ci.tiling = VK_IMAGE_TILING_OPTIMAL;
        ci.usage = kUsage;
        ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
        VkResult r = vkCreateImage(device, &ci, nullptr, &img.image);
        if (r != VK_SUCCESS)
            throw DeviceError(format("cannot create sparse texture image %zu (%ux%u): %s", i,
                                     sizes[i], sizes[i], vkResultName(r)));
        out.images.push_back(img);
        setName(gpu.device, img.image, VK_OBJECT_TYPE_IMAGE, format("streaming.sparse.%zu", i));
        VkMemoryRequirements req;
        vkGetImageMemoryRequirements(device, img.image, &req);
        made.memoryTypeBits &= req.memoryTypeBits;
        made.addressSpace += req.size;
        if (out.pageBytes == 0) out.pageBytes = req.alignment;
        if (req.alignment != out.pageBytes)
            throw DeviceError("sparse texture images with different page sizes");
        SparseLayout layout = sparseLayout(device, img.image);
        const VkSparseImageMemoryRequirements& c = layout.color;
        if (out.granularity.width == 0) { // the device gives compressed formats' in blocks
            out.granularity = c.formatProperties.imageGranularity;
            out.granularity.width *= blockSide(out.format);
            out.granularity.height *= blockSide(out.format);
        }
        // The device's packed tail (none on lavapipe: every level is paged, down to 1x1).
        img.deviceTailFirst = std::min(c.imageMipTailFirstLod, img.levels);
        SparseTexture t;
        t.size = sizes[i];
        // Always resident: the device's tail, and before it the levels smaller than a page
        // (each would take a whole page; paging them saves nothing worth a load).
        t.tailFirst = 0;
        while (t.tailFirst < img.deviceTailFirst &&
               (sizes[i] >> t.tailFirst) >= out.granularity.width &&
               (sizes[i] >> t.tailFirst) >= out.granularity.height)
            t.tailFirst++;
        auto pagesOf = [&](uint32_t l) {
            uint32_t side = std::max(sizes[i] >> l, 1u);
            return blocksAcross(side, out.granularity.width) *
                   blocksAcross(side, out.granularity.height);
        };
        for (uint32_t l = 0; l < t.tailFirst; ++l) t.levelPages.push_back(pagesOf(l));
        for (uint32_t l = t.tailFirst; l < img.deviceTailFirst; ++l)
            out.tailBytes += uint64_t(pagesOf(l)) * out.pageBytes;
        made.book.push_back(std::move(t));
        if (img.deviceTailFirst < img.levels)
            out.tailBytes += alignUp(c.imageMipTailSize, out.pageBytes);
        for (const auto& m : layout.metadata)
            out.tailBytes += alignUp(m.imageMipTailSize, out.pageBytes);
        made.layouts.push_back(std::move(layout));
    }
    return made;
}

// The memory every image binds from: device-local if the images allow it.
void allocateSparseMemory(Gpu& gpu, uint32_t memoryTypeBits, SparseTextures& out) {
    VkDevice device = gpu.device.device;
    const VkPhysicalDeviceMemoryProperties& mp = gpu.device.memory;
    int32_t type = -1;
    for (uint32_t i = 0; i < mp.memoryTypeCount && type < 0; ++i)
        if ((memoryTypeBits & (1u << i)) &&
            (mp.memoryTypes[i].propertyFlags & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT))
            type = int32_t(i);
    for (uint32_t i = 0; i < mp.memoryTypeCount && type < 0; ++i)
        if (memoryTypeBits & (1u << i)) type = int32_t(i);
    if (type < 0) throw DeviceError("no memory type for sparse texture images");
    out.memoryType = uint32_t(type);
    auto allocate = [&](uint64_t bytes, const char* name) {
        VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        ai.allocationSize = bytes;
        ai.memoryTypeIndex = out.memoryType;
        VkDeviceMemory m = VK_NULL_HANDLE;
        if (vkAllocateMemory(device, &ai, nullptr, &m) != VK_SUCCESS)
            throw DeviceError(
                format("out of GPU memory for %s (%.1f MiB)", name, double(bytes) / 1048576.0));
        setName(gpu.device, m, VK_OBJECT_TYPE_DEVICE_MEMORY, name);
        return m;
    };
    out.tailMemory = allocate(out.tailBytes, "streaming.sparse.tails");
    if (out.poolBytes) out.poolMemory = allocate(out.poolBytes, "streaming.sparse.pagePool");
}

// Binds every tail once: the device's opaquely (its layout is the device's business), the
// sub-page levels before it block by block.
void bindSparseTails(Gpu& gpu, const std::vector<uint32_t>& sizes,
                     const std::vector<SparseLayout>& layouts, SparseTextures& out) {
    VkDevice device = gpu.device.device;
    std::vector<std::vector<VkSparseMemoryBind>> tailBinds(out.images.size());
    std::vector<std::vector<VkSparseImageMemoryBind>> levelBinds(out.images.size());
    std::vector<VkSparseImageOpaqueMemoryBindInfo> opaque;
    std::vector<VkSparseImageMemoryBindInfo> blocks;
    uint64_t offset = 0;
    for (size_t i = 0; i < out.images.size(); ++i) {
        for (uint32_t l = out.residency.textures[i].tailFirst; l < out.images[i].deviceTailFirst;
             ++l) {
            uint32_t side = std::max(sizes[i] >> l, 1u);
            uint32_t gw = out.granularity.width, gh = out.granularity.height;
            for (uint32_t by = 0; by < blocksAcross(side, gh); ++by)
                for (uint32_t bx = 0; bx < blocksAcross(side, gw); ++bx) {
                    VkSparseImageMemoryBind b{};
                    b.subresource = {VK_IMAGE_ASPECT_COLOR_BIT, l, 0};
                    b.offset = {int32_t(bx * gw), int32_t(by * gh), 0};
                    b.extent = {std::min(gw, side - bx * gw), std::min(gh, side - by * gh), 1};
                    b.memory = out.tailMemory;
                    b.memoryOffset = offset;
                    offset += out.pageBytes;
                    levelBinds[i].push_back(b);
                }
        }
        if (!levelBinds[i].empty())
            blocks.push_back(
                {out.images[i].image, uint32_t(levelBinds[i].size()), levelBinds[i].data()});
        auto bindTail = [&](const VkSparseImageMemoryRequirements& r, VkSparseMemoryBindFlags f) {
            VkSparseMemoryBind b{};
            b.resourceOffset = r.imageMipTailOffset;
            b.size = r.imageMipTailSize;
            b.memory = out.tailMemory;
            b.memoryOffset = offset;
            b.flags = f;
            tailBinds[i].push_back(b);
            offset += alignUp(r.imageMipTailSize, out.pageBytes);
        };
        if (out.images[i].deviceTailFirst < out.images[i].levels) bindTail(layouts[i].color, 0);
        for (const auto& m : layouts[i].metadata) bindTail(m, VK_SPARSE_MEMORY_BIND_METADATA_BIT);
        if (!tailBinds[i].empty())
            opaque.push_back(
                {out.images[i].image, uint32_t(tailBinds[i].size()), tailBinds[i].data()});
    }
    SHADEL_ASSERT(offset <= out.tailBytes);
    VkBindSparseInfo bi{VK_STRUCTURE_TYPE_BIND_SPARSE_INFO};
    bi.imageOpaqueBindCount = uint32_t(opaque.size());
    bi.pImageOpaqueBinds = opaque.data();
    bi.imageBindCount = uint32_t(blocks.size());
    bi.pImageBinds = blocks.data();
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence = VK_NULL_HANDLE;
    VK_CHECK(vkCreateFence(device, &fci, nullptr, &fence));
    VK_CHECK(vkQueueBindSparse(gpu.device.queue, 1, &bi, fence));
    VK_CHECK(vkWaitForFences(device, 1, &fence, VK_TRUE, ~0ull)); // creation, not a frame
    vkDestroyFence(device, fence, nullptr);
}

// One view per texture and possible resident level.
void createSparseViews(Gpu& gpu, const std::vector<bool>& srgb, SparseTextures& out) {
    VkDevice device = gpu.device.device;
    for (size_t i = 0; i < out.images.size(); ++i) {
        SparseImage& img = out.images[i];
        for (uint32_t base = 0; base <= out.residency.textures[i].tailFirst; ++base) {
            VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
            vi.image = img.image;
            vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
            vi.format = packedVkFormat(out.format, srgb[i]);
            vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, base, img.levels - base, 0, 1};
            VkImageView v = VK_NULL_HANDLE;
            VK_CHECK(vkCreateImageView(device, &vi, nullptr, &v));
            setName(gpu.device, v, VK_OBJECT_TYPE_IMAGE_VIEW,
                    format("streaming.sparse.%zu.fromLevel%u", i, base));
            img.views.push_back(v);
        }
    }
}

} // namespace

VkFormat packedVkFormat(BlockFormat format, bool srgb) {
    if (format == BlockFormat::Bc7)
        return srgb ? VK_FORMAT_BC7_SRGB_BLOCK : VK_FORMAT_BC7_UNORM_BLOCK;
    if (format == BlockFormat::Bc5) return VK_FORMAT_BC5_UNORM_BLOCK;
    if (format == BlockFormat::Bc4) return VK_FORMAT_BC4_UNORM_BLOCK;
    return srgb ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_R8G8B8A8_UNORM;
}

std::string sparseUnsupportedReason(const Gpu& gpu, BlockFormat format) {
    const Device& d = gpu.device;
    if (!d.optional.sparseResidency)
        return d.name + " has no sparse residency for 2-D images (sparseBinding, "
                        "sparseResidencyImage2D and a sparse-binding queue)";
    for (bool srgb : {false, true}) {
        uint32_t n = 0;
        vkGetPhysicalDeviceSparseImageFormatProperties(
            d.physical, packedVkFormat(format, srgb), VK_IMAGE_TYPE_2D, VK_SAMPLE_COUNT_1_BIT,
            kUsage, VK_IMAGE_TILING_OPTIMAL, &n, nullptr);
        if (n == 0)
            return d.name + " cannot make sparse-resident " + blockFormatName(format) +
                   (srgb ? " sRGB" : " linear") + " images";
    }
    return {};
}

void createSparseTextures(Gpu& gpu, const std::vector<uint32_t>& sizes,
                          const std::vector<bool>& srgb, BlockFormat blockFormat,
                          uint64_t budgetBytes, SparseTextures& out) {
    VkDevice device = gpu.device.device;
    out.gpu = &gpu;
    out.format = blockFormat;
    SparseImagesMade made = createSparseImages(gpu, sizes, srgb, out);
    const uint64_t addressSpace = made.addressSpace;
    if (addressSpace > gpu.device.properties.limits.sparseAddressSpaceSize)
        throw InputError(
            format("--streaming sparse: the %zu textures need %.0f MiB of sparse "
                   "address space, the device has %.0f MiB",
                   sizes.size(), double(addressSpace) / 1048576.0,
                   double(gpu.device.properties.limits.sparseAddressSpaceSize) / 1048576.0));
    if (out.tailBytes > budgetBytes)
        throw InputError(format("--texture-budget %.2f: below the %.2f MiB the %zu textures' "
                                "sparse MIP tails need",
                                double(budgetBytes) / 1048576.0, double(out.tailBytes) / 1048576.0,
                                sizes.size()));
    out.residency = makeSparseResidency(std::move(made.book),
                                        uint32_t((budgetBytes - out.tailBytes) / out.pageBytes));
    out.poolBytes = uint64_t(out.residency.poolPages) * out.pageBytes;

    allocateSparseMemory(gpu, made.memoryTypeBits, out);
    bindSparseTails(gpu, sizes, made.layouts, out);
    createSparseViews(gpu, srgb, out);
    VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VK_CHECK(vkCreateSemaphore(device, &sci, nullptr, &out.bound));
    setName(gpu.device, out.bound, VK_OBJECT_TYPE_SEMAPHORE, "streaming.sparse.bound");
    SHADEL_INFO("sparse textures: %zu images, %ux%u-texel pages of %llu KiB, tails %.2f MiB, "
                "pool %u pages (%.2f MiB)",
                out.images.size(), out.granularity.width, out.granularity.height,
                (unsigned long long)(out.pageBytes / 1024), double(out.tailBytes) / 1048576.0,
                out.residency.poolPages, double(out.poolBytes) / 1048576.0);
}

void destroySparseTextures(SparseTextures& s) {
    if (!s.gpu) return;
    VkDevice device = s.gpu->device.device;
    for (SparseImage& img : s.images) {
        for (VkImageView v : img.views) vkDestroyImageView(device, v, nullptr);
        vkDestroyImage(device, img.image, nullptr);
    }
    if (s.tailMemory) vkFreeMemory(device, s.tailMemory, nullptr);
    if (s.poolMemory) vkFreeMemory(device, s.poolMemory, nullptr);
    if (s.bound) vkDestroySemaphore(device, s.bound, nullptr);
    s = SparseTextures{};
}

VkImageView sparseResidentView(const SparseTextures& s, uint32_t texture) {
    return s.images[texture].views[s.residency.textures[texture].resident];
}

VkSemaphore submitSparseBinds(SparseTextures& s, const std::vector<const SparseLevelLoad*>& binds,
                              const std::vector<SparseEviction>& unbinds) {
    if (binds.empty() && unbinds.empty()) return VK_NULL_HANDLE;
    // Per image, its blocks of the level in row-major order, each to its page (or to nothing).
    std::vector<std::vector<VkSparseImageMemoryBind>> perImage(s.images.size());
    auto level = [&](int32_t texture, uint32_t lvl, const std::vector<uint32_t>& pages, bool bind) {
        uint32_t side = s.residency.textures[texture].size >> lvl;
        uint32_t gw = s.granularity.width, gh = s.granularity.height;
        uint32_t across = blocksAcross(side, gw), k = 0;
        for (uint32_t by = 0; by < blocksAcross(side, gh); ++by)
            for (uint32_t bx = 0; bx < across; ++bx, ++k) {
                VkSparseImageMemoryBind b{};
                b.subresource = {VK_IMAGE_ASPECT_COLOR_BIT, lvl, 0};
                b.offset = {int32_t(bx * gw), int32_t(by * gh), 0};
                b.extent = {std::min(gw, side - bx * gw), std::min(gh, side - by * gh), 1};
                b.memory = bind ? s.poolMemory : VK_NULL_HANDLE;
                b.memoryOffset = bind ? uint64_t(pages[k]) * s.pageBytes : 0;
                perImage[texture].push_back(b);
            }
        (bind ? s.pageBinds : s.pageUnbinds) += k;
    };
    for (const SparseEviction& e : unbinds) level(e.texture, e.level, e.pages, false);
    for (const SparseLevelLoad* l : binds) {
        size_t k = 0;
        for (uint32_t lvl = l->level; lvl < l->level + l->levels; ++lvl) {
            uint32_t n = s.residency.textures[l->texture].levelPages[lvl];
            level(l->texture, lvl,
                  std::vector<uint32_t>(l->pages.begin() + k, l->pages.begin() + k + n), true);
            k += n;
        }
    }
    std::vector<VkSparseImageMemoryBindInfo> infos;
    for (size_t i = 0; i < perImage.size(); ++i)
        if (!perImage[i].empty())
            infos.push_back({s.images[i].image, uint32_t(perImage[i].size()), perImage[i].data()});
    VkBindSparseInfo bi{VK_STRUCTURE_TYPE_BIND_SPARSE_INFO};
    bi.imageBindCount = uint32_t(infos.size());
    bi.pImageBinds = infos.data();
    bi.signalSemaphoreCount = 1;
    bi.pSignalSemaphores = &s.bound;
    VK_CHECK(vkQueueBindSparse(s.gpu->device.queue, 1, &bi, VK_NULL_HANDLE));
    return s.bound;
}

} // namespace shadel
