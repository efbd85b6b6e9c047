#pragma once
// A uniform grid over the instances' world boxes, so CPU work that only concerns instances
// near the view (the decoupled path's coarse allocation) visits those, not every instance: the
// frontend's cost follows what the camera sees, not the size of the world.
#include <cstdint>
#include <vector>

#include "common/shared_types.h"
#include "scene/scene.h"

namespace shadel {

class InstanceGrid {
public:
    // About `instancesPerCell` instances a cell; instances more than two cells across are kept
    // aside and visited by every query.
    void build(const std::vector<gpu::GpuInstance>& instances, float instancesPerCell = 4.0f);
    // Appends to `out` every instance whose box, grown by 10% of its size on each side, may
    // overlap `box` (a superset; each once).
    void query(const Aabb& box, std::vector<uint32_t>& out) const;
    size_t cellCount() const { return cellStart_.empty() ? 0 : cellStart_.size() - 1; }
    size_t largeCount() const { return large_.size(); }

private:
    Aabb bounds_;
    glm::ivec3 dims_{1};
    glm::vec3 cellSize_{1.0f};
    std::vector<uint32_t> cellStart_; // CSR: items of cell c are items_[cellStart_[c] ..)
    std::vector<uint32_t> items_;
    std::vector<uint32_t> large_;
};

} // namespace shadel
