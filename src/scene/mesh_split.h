#pragma once
// Splitting a mesh into chunks on an axis-aligned grid ("all objects, even chunks of world", seed
// 000): a mesh far larger than the distances it is seen from cannot get one shadel density that
// suits its near and far parts, nor fit one chart atlas; its chunks can.
//
// Triangles are clipped exactly against the grid planes x, y, z = k * cell (object space, k an
// integer), so every piece lies in one grid cell. Clipping is watertight: a new vertex on an edge
// is computed from the edge's endpoints in a canonical order, so the two triangles sharing the
// edge get bit-identical vertices (no T-junctions, no cracks). Attributes are interpolated
// linearly along the edge, which is what the rasterizer does, so a split mesh draws the same
// surface with the same shading inputs. Triangles no plane crosses keep their vertices as they
// are. Cells are then grouped top-down over an octree of the grid: a node becomes one chunk when
// `wholeNode(its tight object-space bounds)` says so (or it is a single cell).
//
// Deterministic: the same mesh, cell and decisions give the same chunks in the same order.
#include <functional>
#include <vector>

#include "scene/scene.h"

namespace shadel {

// Returns the chunks (each with the mesh's material, name "<name> chunk <i>"), or the mesh
// unchanged (one element) when `wholeNode(mesh.bounds)` keeps it whole. `cell` > 0.
std::vector<Mesh> splitMeshOnGrid(const Mesh& mesh, float cell,
                                  const std::function<bool(const Aabb& objectBounds)>& wholeNode);

} // namespace shadel
