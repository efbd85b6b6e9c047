#pragma once
// Shadel baking: a unique chart atlas ("shadel UVs") and per-MIP triangle-ID maps per mesh.
//
// Resolution and blocks. A mesh's charts are laid out at `shadelsPerMetre` shadels per metre of
// object-space surface (at most: conformal charts are scaled never to magnify, so parts of them
// get up to stretch^2 fewer shadels per m^2, see stretch.h), packed with gutters into a near-square
// rect whose sides are rounded up to multiples of 8 (one chunk) and clamped to [minResolution,
// maxResolution]. The renderer places the object in the virtual sheet in 64x64-shadel blocks: at
// MIP k the object needs ceil((width >> k) / 64) x ceil((height >> k) / 64) blocks, and once a side
// drops below 64 it is snapped up to one block (small MIPs snap to a whole block). The density is
// raised above the setting only when needed: for tiny objects (to fill minResolution) and for
// meshes whose triangles are too small for each to own a shadel at MIP 0; lowered only to fit
// maxResolution. BakedMesh::shadelsPerMetre is the density actually used.
//
// Chart variants. A mesh of few charts whose layout covers little of its rect (at the requested
// density, not padded, rect <= 512^2) is charted again with wider first-growth cones (charting.h)
// and the layout covering the most of its rect is kept: deterministic, and never worse.
//
// MIP levels. ID maps exist for levels k = 0 .. mipCount-1 with mipCount = 1 + floor(log2(
// min(width, height) / 8)): the coarsest level is the first where a side is one chunk (8).
// Coarser levels would still occupy one chunk and one block, so they save no storage; the
// renderer clamps its MIP to mipCount-1 (the object is then a few pixels tall on screen and
// over-shades by a bounded amount). The packer keeps rects near-square so both sides hit 8
// together.
//
// Gutters. Charts are packed by their outlines: the shadels they touch grown by gutterShadels on
// every side (chart_packing.h), and outlines never overlap, so charts are >= 2*g MIP-0 shadels
// apart. Outlines may overhang the rect border (a chart may touch it): the renderer clamps taps
// to the rect, so a tap past the border reads the chart's own border shadel. A bilinear tap at MIP
// k reads shadels whose centres lie within 2^k MIP-0 shadels of the sample, so two charts never
// compete for a shadel the filter reads while 2 * 2^k <= 2 * g, i.e. for all k <= log2(g) (g = 2:
// MIPs 0 and 1, and the trilinear blend between them). Every level's ID map is flooded: each empty
// shadel near a chart takes the ID of the *nearest* triangle (true 2-D distance, not flood steps),
// so within the clean levels every shadel a filter reads belongs to the sampled chart and
// extrapolates the right surface. Coarser levels can mix neighbouring charts in shared shadels (the
// usual mipmap chart bleeding) but every shadel the filter reads still has a valid ID, so shading
// never reads an unshaded shadel. The renderer must clamp shadel coordinates to [0, (W>>k) - 1] so
// taps on the rect border never leave the object's rect at coarse levels.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/mesh_utils.h" // kMaxTrianglesPerMesh (16-bit IDs, 0xFFFF reserved)
#include "scene/scene.h"

namespace shadel {

constexpr uint16_t kEmptyShadel = 0xFFFF;

struct BakeSettings {
    float shadelsPerMetre = 32.0f;
    uint32_t maxResolution = 4096;
    uint32_t minResolution = 8;
    uint32_t gutterShadels = 2;  // padding on each side of every chart, MIP-0 shadels
    float chartConeDegrees = 40; // charts grow over triangles within this angle of the chart
    uint32_t threads = 2;        // bakeScene workers
    // bakeScene: least-recently-used cache files beyond this are removed (0 = no limit). Not
    // part of the bake key: it does not change what is baked.
    uint64_t cacheLimitBytes = 4ull << 30;
};

struct BakedMesh {
    // Vertices are re-indexed so each has one shadel UV (duplicated along chart seams).
    std::vector<uint32_t> vertexRemap; // baked vertex -> source Mesh vertex
    std::vector<glm::vec2> shadelUv;   // per baked vertex, in [0,1]^2 of the object's shadel rect
    std::vector<uint32_t> indices;     // same triangle order as the source (triangle ID = i/3)
    uint32_t width = 0, height = 0;    // MIP-0 shadel resolution, multiples of 8 (chunk)
    // Per MIP level k: (width >> k) x (height >> k) triangle IDs, row-major; kEmptyShadel = empty.
    std::vector<std::vector<uint16_t>> idMaps;
    uint32_t chartCount = 0;
    float utilisation = 0;     // shadels covered by a triangle (centre rule) / width*height
    float shadelsPerMetre = 0; // density actually used, per object-space unit (see above)
    uint32_t triangleCount = 0;
    uint32_t degenerateTriangles = 0; // zero-area triangles, given one private shadel each
    uint32_t forcedTriangles = 0;     // triangles that got their MIP-0 shadel by force-assignment
    uint32_t unownedTriangles = 0;    // triangles with no MIP-0 shadel (0 unless maxResolution hit)
    double surfaceArea = 0;           // object-space m^2 of non-degenerate triangles
    // Shadel spacing on the surface relative to the density, over chart triangles (1 = no
    // distortion; stretch.h): area-weighted mean and worst chart.
    float meanStretch = 1, maxStretch = 1;
    double bakeSeconds = 0; // wall time of the bake (or of the cache load)
    bool fromCache = false;

    uint32_t mipCount() const { return uint32_t(idMaps.size()); }
    uint32_t levelWidth(uint32_t level) const { return width >> level; }
    uint32_t levelHeight(uint32_t level) const { return height >> level; }
};

// Number of ID-map levels for a MIP-0 rect of width x height (see header comment).
uint32_t bakedMipCount(uint32_t width, uint32_t height);

// Bakes one mesh. Throws InputError for meshes the baker cannot represent (more than
// kMaxTrianglesPerMesh triangles, indices out of range).
BakedMesh bakeMesh(const Mesh& mesh, const BakeSettings& settings);

using BakeProgress = std::function<void(size_t done, size_t total)>;

// Bakes every mesh of the scene (result[i] belongs to scene.meshes[i]) at settings.shadelsPerMetre
// per metre of world surface: a mesh is baked at that density times the largest scale of the
// instances using it (BakedMesh::shadelsPerMetre is then per object-space unit). Meshes with
// identical content are baked once; results are read from / written to cacheDir (empty: no cache).
// Uses settings.threads workers; output does not depend on the thread count. `progress` is called
// on the calling thread, once with done = 0 and then after each distinct mesh.
// `meshDensity` (optional, one per mesh, shadels per object-space unit; <= 0 = use the rule
// above) overrides the density per mesh, e.g. the view-driven one (render/view_density.h).
std::vector<BakedMesh> bakeScene(const Scene& scene, const BakeSettings& settings,
                                 const std::string& cacheDir, const BakeProgress& progress = {},
                                 const std::vector<float>& meshDensity = {});

// Human-readable summary for `shadel bake`: meshes, triangles, charts, utilisation, density,
// forced/unowned triangles, cache hits and bake time.
std::string bakeReport(const std::vector<BakedMesh>& meshes, double wallSeconds);

// Shadel density for a scene: `requested` shadels per metre, lowered when the scene's
// surface (each mesh at its largest instance scale) would need more than `budget` MIP-0
// shadels. `area` receives that surface. Unit-less CAD files in millimetres are the usual case.
float sceneShadelDensity(const Scene& scene, float requested, double budget, double& area);

} // namespace shadel
