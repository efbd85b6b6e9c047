#include "render/shadel/shadel_sheet.h"

#include <algorithm>
#include <optional>
#include <utility>

#include "render/gpu_scene.h"

namespace shadel {

namespace {

// The part of a level a rect holds, in level blocks.
struct LevelWindow {
    glm::uvec2 origin{0}, size{0};
};

} // namespace

static void writeAllocId(Gpu& gpu, DecoupledState& d, const glm::uvec4& rect, uint32_t value) {
    auto* ids = static_cast<uint32_t*>(mapped(gpu, d.allocId));
    for (uint32_t y = rect.y; y < rect.y + rect.w; ++y)
        for (uint32_t x = rect.x; x < rect.x + rect.z; ++x)
            ids[size_t(y) * d.sheetBlocks + x] = value;
}

static void freeLevel(Gpu& gpu, DecoupledState& d, ObjectSlot& o, uint32_t k) {
    if (!o.ids[k].valid()) return;
    d.regions[k].allocator->remove(o.ids[k]);
    writeAllocId(gpu, d, o.rects[k], 0);
    o.ids[k] = BlockId{};
}

void freeObject(Gpu& gpu, DecoupledState& d, ObjectSlot& o) {
    for (uint32_t k = 0; k < o.mipCount; ++k) freeLevel(gpu, d, o, k);
    o.allocated = false;
}

glm::uvec2 levelBlocks(const ShadelMeshInfo& mesh, uint32_t k) {
    uint32_t w = std::max(1u, mesh.mip0Size.x >> k), h = std::max(1u, mesh.mip0Size.y >> k);
    return {(w + SHADEL_BLOCK - 1) / SHADEL_BLOCK, (h + SHADEL_BLOCK - 1) / SHADEL_BLOCK};
}

// Level windows. The finest levels of a large object are mostly unread: of builtin:default's
// 7814 rect blocks at 1280x720, 796 hold a marked chunk (the rest is occluded, off screen or
// seen at a coarser MIP, which only the GPU's marks can tell). So a fine level's rect holds
// only a window of the level: the blocks last frame's samples wanted there (marked, or wanted
// but read coarser because the window did not hold them: marking.glsl wantLevel), plus a
// margin for the view's motion; a level nothing wanted holds no blocks at all (most levels of
// builtin:many's 4000 small objects). A sample outside the window reads the next coarser level
// for a frame (counted: window_fallback_pixel_fraction), never a hole; one lagging by more than
// a level (a camera cut) is shaded forward instead (window_forward_pixel_fraction, shadel.glsl
// windowFallbackTooDeep). The coarsest level and levels with no feedback yet (just placed) are
// held whole.

static LevelWindow wholeLevel(const ShadelMeshInfo& mesh, uint32_t k) {
    return {glm::uvec2(0), levelBlocks(mesh, k)};
}

static LevelWindow currentWindow(const ObjectSlot& o, uint32_t k) {
    return {o.windowOrigin[k], {o.rects[k].z, o.rects[k].w}};
}

// The window the level should hold this frame: the wanted blocks, grown on each side by one
// block and a quarter of their extent (the view's motion over a frame), within the level.
// The level blocks last frame wanted at level k or at its neighbours k - 1 and k + 1 (scaled
// to level k): a surface moving across a LOD boundary then finds the next level already
// there. {lo, hi} in level k blocks, lo >= hi when nothing was wanted.
static std::pair<glm::uvec2, glm::uvec2> wantedBlocks(const DecoupledState& d, const ObjectSlot& o,
                                                      const ShadelMeshInfo& mesh, uint32_t k) {
    glm::uvec2 lo{~0u}, hi{0u};
    auto add = [&](uint32_t level, auto toK) {
        if (level >= mesh.mipCount || o.wantedFor[level] != d.frameNumber + 1) return;
        const glm::uvec4& w = o.wanted[level];
        if (w.x >= w.z || w.y >= w.w) return;
        auto [a, b] = toK(glm::uvec2(w.x, w.y), glm::uvec2(w.z, w.w));
        lo = glm::min(lo, a);
        hi = glm::max(hi, b);
    };
    add(k, [](glm::uvec2 a, glm::uvec2 b) { return std::pair{a, b}; });
    if (k > 0)
        add(k - 1, [](glm::uvec2 a, glm::uvec2 b) { return std::pair{a / 2u, (b + 1u) / 2u}; });
    add(k + 1, [](glm::uvec2 a, glm::uvec2 b) { return std::pair{a * 2u, b * 2u}; });
    glm::uvec2 size = levelBlocks(mesh, k);
    return {glm::min(lo, size), glm::min(hi, size)};
}

static LevelWindow targetWindow(const DecoupledState& d, const ObjectSlot& o,
                                const ShadelMeshInfo& mesh, uint32_t k) {
    LevelWindow whole = wholeLevel(mesh, k);
    if (!d.levelWindows || k + 1 >= mesh.mipCount || o.wantedFor[k] != d.frameNumber + 1)
        return whole;
    auto [lo, hi] = wantedBlocks(d, o, mesh, k);
    // Nothing wanted (occluded, or seen only at other levels): an empty window; samples read
    // coarser and their wants bring the level back next frame.
    if (lo.x >= hi.x || lo.y >= hi.y) return {};
    glm::uvec2 margin = 1u + (hi - lo) / 4u;
    lo -= glm::min(lo, margin);
    hi = glm::min(hi + margin, whole.size);
    return {lo, hi - lo};
}

// Hysteresis: the level keeps its window (and its place; a moved window's shadels are carried
// over where the old window held them, but the blocks it newly holds are shaded) while the window
// holds the wanted blocks with one block to spare and is at most twice the target's area; a view
// hovering at an edge does not move the rect every frame.
static bool keepWindow(const DecoupledState& d, const ObjectSlot& o, const ShadelMeshInfo& mesh,
                       uint32_t k, LevelWindow target) {
    LevelWindow now = currentWindow(o, k);
    if (now.origin == target.origin && now.size == target.size) return true;
    LevelWindow whole = wholeLevel(mesh, k);
    if (target.size == whole.size) return false; // whole again (no feedback, or windows off)
    if (target.size.x * target.size.y == 0) return false; // nothing wanted: give it back
    // A non-empty target means something was wanted: it must stay inside with a block to spare.
    auto [lo, hi] = wantedBlocks(d, o, mesh, k);
    lo -= glm::min(lo, glm::uvec2(1u));
    hi = glm::min(hi + 1u, whole.size);
    if (glm::any(glm::lessThan(lo, now.origin)) ||
        glm::any(glm::greaterThan(hi, now.origin + now.size)))
        return false;
    return uint64_t(now.size.x) * now.size.y <= 2 * uint64_t(target.size.x) * target.size.y;
}

static void setLevelRect(Gpu& gpu, DecoupledState& d, ObjectSlot& o, uint32_t object, uint32_t k,
                         const Placement<2>& placed, LevelWindow window) {
    o.ids[k] = placed.id;
    o.levelSince[k] = d.frameNumber;
    o.windowOrigin[k] = window.origin;
    o.rects[k] = {d.regions[k].x0 + placed.origin[0], placed.origin[1], window.size.x,
                  window.size.y};
    writeAllocId(gpu, d, o.rects[k], ((object + 1) << 4) | k);
}

static bool allocateLevel(Gpu& gpu, DecoupledState& d, ObjectSlot& o, uint32_t object,
                          const ShadelMeshInfo& mesh, uint32_t k) {
    LevelWindow window = targetWindow(d, o, mesh, k);
    auto placed = d.regions[k].allocator->insert(Extent<2>{window.size.x, window.size.y});
    if (!placed) return false;
    setLevelRect(gpu, d, o, object, k, *placed, window);
    return true;
}

// A level whose window changed is placed again (the new rect first, so a full sheet keeps the
// old window rather than losing the level).
static void updateLevelWindow(Gpu& gpu, DecoupledState& d, ObjectSlot& o, uint32_t object,
                              const ShadelMeshInfo& mesh, uint32_t k) {
    LevelWindow target = targetWindow(d, o, mesh, k);
    if (keepWindow(d, o, mesh, k, target)) return;
    std::optional<Placement<2>> placed;
    if (target.size.x * target.size.y != 0) {
        placed = d.regions[k].allocator->insert(Extent<2>{target.size.x, target.size.y});
        if (!placed) {
            o.windowRetry = true;
            return;
        }
    }
    if (placed && o.ids[k].valid()) { // moved: what the old window held can be carried over
        o.movedFromRect[k] = o.rects[k];
        o.movedFromWindow[k] = o.windowOrigin[k];
        o.movedAt[k] = d.frameNumber;
    }
    freeLevel(gpu, d, o, k);
    d.windowMoves++;
    if (placed) return setLevelRect(gpu, d, o, object, k, *placed, target);
    o.levelSince[k] = d.frameNumber; // empty: no rect, no blocks
    o.windowOrigin[k] = glm::uvec2(0);
    o.rects[k] = {d.regions[k].x0, 0, 0, 0};
}

bool updateObjectRects(Gpu& gpu, DecoupledState& d, ObjectSlot& o, uint32_t object,
                       const ShadelMeshInfo& mesh, uint32_t wantFirst, bool wasDecoupled,
                       bool& limited) {
    limited = false;
    if (!o.allocated) {
        o.mipCount = mesh.mipCount;
        o.firstMip = mesh.mipCount;
        o.allocated = true;
        o.firstMipChanged = d.frameNumber;
    }
    uint32_t firstMip = o.firstMip;
    while (o.firstMip > wantFirst && allocateLevel(gpu, d, o, object, mesh, o.firstMip - 1))
        --o.firstMip;
    if (o.firstMip > wantFirst) limited = true; // the sheet is full: clamped to coarser levels
    while (o.firstMip + 1 < wantFirst) freeLevel(gpu, d, o, o.firstMip++);
    if (o.firstMip == o.mipCount) { // not even the coarsest level fits
        o.allocated = false;
        return false;
    }
    if (o.firstMip != firstMip) o.firstMipChanged = d.frameNumber;
    // The wants and levels are those the last update (last frame's) kept or placed: it would
    // keep every window again (most objects of a steady view).
    bool settled =
        wasDecoupled && o.wantsSettled && !o.windowRetry && o.firstMipChanged + 2 <= d.frameNumber;
    if (settled) return true;
    o.windowRetry = false;
    for (uint32_t k = o.firstMip; k < o.mipCount; ++k)
        if (o.levelSince[k] < d.frameNumber) updateLevelWindow(gpu, d, o, object, mesh, k);
    return true;
}

} // namespace shadel
