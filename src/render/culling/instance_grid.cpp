#include "render/culling/instance_grid.h"

#include <algorithm>
#include <cmath>

namespace shadel {

void InstanceGrid::build(const std::vector<gpu::GpuInstance>& instances, float instancesPerCell) {
    bounds_ = Aabb{};
    for (const auto& i : instances) bounds_.extend(Aabb{i.worldMin, i.worldMax});
    cellStart_.assign(2, 0);
    items_.clear();
    large_.clear();
    dims_ = glm::ivec3(1);
    if (instances.empty() || !bounds_.valid()) return;
    // Cubic cells sized for the wanted count; flat axes (a city's height) get one cell.
    glm::vec3 extent = glm::max(bounds_.max - bounds_.min, glm::vec3(1e-3f));
    double cells = std::max(1.0, double(instances.size()) / instancesPerCell);
    double side = std::cbrt(double(extent.x) * extent.y * extent.z / cells);
    // Axes shorter than a cell get one cell; the others share the count.
    for (int pass = 0; pass < 3; ++pass) {
        double longProduct = 1.0;
        int axes = 0;
        for (int a = 0; a < 3; ++a)
            if (extent[a] > side) longProduct *= extent[a], ++axes;
        if (axes == 0) break;
        side = std::pow(longProduct / cells, 1.0 / axes);
    }
    for (int a = 0; a < 3; ++a) dims_[a] = std::clamp(int(std::ceil(extent[a] / side)), 1, 1 << 12);
    cellSize_ = extent / glm::vec3(dims_);
    size_t cellTotal = size_t(dims_.x) * dims_.y * dims_.z;
    std::vector<uint32_t> cellOf(instances.size(), UINT32_MAX);
    std::vector<uint32_t> count(cellTotal + 1, 0);
    for (size_t i = 0; i < instances.size(); ++i) {
        glm::vec3 size = instances[i].worldMax - instances[i].worldMin;
        if (glm::any(glm::greaterThan(size, 2.0f * cellSize_))) {
            large_.push_back(uint32_t(i));
            continue;
        }
        glm::vec3 centre = 0.5f * (instances[i].worldMin + instances[i].worldMax);
        glm::ivec3 c =
            glm::clamp(glm::ivec3((centre - bounds_.min) / cellSize_), glm::ivec3(0), dims_ - 1);
        cellOf[i] = uint32_t((size_t(c.z) * dims_.y + c.y) * dims_.x + c.x);
        count[cellOf[i] + 1]++;
    }
    for (size_t c = 0; c < cellTotal; ++c) count[c + 1] += count[c];
    cellStart_ = count;
    items_.resize(count[cellTotal]);
    for (size_t i = 0; i < instances.size(); ++i)
        if (cellOf[i] != UINT32_MAX) items_[count[cellOf[i]]++] = uint32_t(i);
}

void InstanceGrid::query(const Aabb& box, std::vector<uint32_t>& out) const {
    out.insert(out.end(), large_.begin(), large_.end());
    if (items_.empty() || !box.valid()) return;
    // A small instance (at most two cells across, so up to 1.2 cells from its centre with a
    // 10% margin) lies within two cells of the cell holding its centre.
    glm::vec3 top = glm::vec3(dims_);
    glm::ivec3 lo(
        glm::clamp(glm::floor((box.min - bounds_.min) / cellSize_) - 2.0f, glm::vec3(0), top));
    glm::ivec3 hi(glm::clamp(glm::floor((box.max - bounds_.min) / cellSize_) + 2.0f, glm::vec3(-1),
                             top - 1.0f));
    for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
            for (int x = lo.x; x <= hi.x; ++x) {
                size_t c = (size_t(z) * dims_.y + y) * dims_.x + x;
                out.insert(out.end(), items_.begin() + cellStart_[c],
                           items_.begin() + cellStart_[c + 1]);
            }
}

} // namespace shadel
