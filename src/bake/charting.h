#pragma once
// Charting: splits a mesh into charts that flatten without overlap and with little distortion,
// and gives every chart vertex a 2-D coordinate in metres. Scale-free: packing decides density.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace shadel {

enum class ChartKind : uint8_t {
    Planar,          // triangles projected on the plane of their mean normal; coords in metres
    DegenerateCells, // zero-area triangles, one unit cell each; coords in shadels, never scaled
};

struct Chart {
    ChartKind kind = ChartKind::Planar;
    uint32_t firstVertex = 0; // baked vertices of a chart are contiguous
    uint32_t vertexCount = 0;
    glm::dvec2 extent{0.0}; // local coords lie in [0, extent]; extent.x >= extent.y
    double surfaceArea = 0; // object-space m^2
};

struct ChartedMesh {
    std::vector<uint32_t> vertexRemap; // baked vertex -> source vertex
    std::vector<glm::dvec2> local;     // baked vertex -> chart-local 2-D coordinate
    std::vector<uint32_t> indices;     // baked indices, source triangle order
    std::vector<Chart> charts;
    uint32_t degenerateTriangles = 0;
    double surfaceArea = 0;
};

struct ChartingSettings {
    float coneDegrees = 40.0f;
};

// Throws InputError if an index is out of range.
ChartedMesh buildCharts(const Mesh& mesh, const ChartingSettings& settings);

} // namespace shadel
