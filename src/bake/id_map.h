#pragma once
// Triangle-ID maps: which triangle every shadel of one MIP level belongs to.
//
// Built in two passes merged: a standard pass (shadel centres, top-left rule), a conservative pass
// (any positive-area overlap of triangle and shadel square) that fills only shadels the first
// pass left empty, then a flood of the IDs into the empty shadels around the charts. Where
// several triangles compete for a shadel (conservative pass, flood) the one nearest to the shadel
// centre wins, so gutter shadels extrapolate the closest surface. All coverage tests run on
// 1/256-shadel fixed point, so triangles sharing an edge partition its shadels exactly.
#include <cstdint>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

namespace shadel {

struct IdMapOptions {
    uint32_t floodPasses = 3;    // rings of empty shadels filled around the charts
    bool forceOwnership = false; // give every triangle >= 1 shadel (done at MIP 0)
};

struct IdMapStats {
    uint64_t coveredShadels = 0;      // standard-pass shadels
    uint64_t conservativeShadels = 0; // shadels filled by the conservative pass
    uint64_t floodedShadels = 0;
    uint32_t forcedTriangles = 0;  // owned nothing after the merge; were given a shadel
    uint32_t unownedTriangles = 0; // still own nothing (only with forceOwnership)
};

// uv: per vertex, in [0,1]^2; the level is width x height shadels (see shadel_bary.h for the
// coordinate convention). Triangle IDs are indices / 3 and must be < 0xFFFF.
std::vector<uint16_t> buildIdMap(const std::vector<glm::vec2>& uv,
                                 const std::vector<uint32_t>& indices, uint32_t width,
                                 uint32_t height, const IdMapOptions& options, IdMapStats* stats);

// Standard coverage only: visit(triangle, x, y) for every shadel whose centre the triangle
// covers under the top-left rule. For validation (overlap counting).
void forEachCoveredShadel(const std::vector<glm::vec2>& uv, const std::vector<uint32_t>& indices,
                          uint32_t width, uint32_t height,
                          const std::function<void(uint32_t, uint32_t, uint32_t)>& visit);

} // namespace shadel
