#include "bake/bake_cache_check.h"

#include <cmath>
#include <vector>

#include "bake/id_map.h"
#include "core/log.h"

namespace shadel {

std::string bakeContradictsMesh(const Mesh& mesh, const BakedMesh& b) {
    if (b.triangleCount != mesh.triangleCount() || b.indices.size() != mesh.indices.size())
        return "triangle count differs from the mesh";
    for (uint32_t k = 0; k < b.mipCount(); ++k) {
        const std::vector<uint16_t>& ids = b.idMaps[k];
        uint32_t width = b.levelWidth(k), height = b.levelHeight(k);
        uint64_t covered = 0, wrong = 0;
        forEachCoveredShadel(b.shadelUv, b.indices, width, height,
                             [&](uint32_t triangle, uint32_t x, uint32_t y) {
                                 ++covered;
                                 wrong += ids[size_t(y) * width + x] != triangle;
                             });
        // Force-assignment (MIP 0 only) may take one covered shadel per forced triangle.
        uint64_t allowed = k == 0 ? b.forcedTriangles : 0;
        if (wrong > allowed)
            return format("MIP %u: %llu covered shadels hold another triangle's ID", k,
                          (unsigned long long)wrong);
        if (k == 0) {
            double area = double(width) * height;
            if (std::abs(double(covered) - double(b.utilisation) * area) > 1.0 + 1e-5 * area)
                return "covered shadels do not match the recorded utilisation";
        }
    }
    std::vector<bool> owns(b.triangleCount, false);
    for (uint16_t id : b.idMaps[0])
        if (id != kEmptyShadel) owns[id] = true;
    uint32_t owners = 0;
    for (bool o : owns) owners += o;
    if (owners + b.unownedTriangles < b.triangleCount)
        return format("%u of %u triangles own no MIP-0 shadel (%u recorded)",
                      b.triangleCount - owners, b.triangleCount, b.unownedTriangles);
    return {};
}

} // namespace shadel
