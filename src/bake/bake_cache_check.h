#pragma once
// A bake read from the cache is checked against the mesh it claims to describe, beyond its
// checksum: a file edited with a recomputed checksum (swapped sizes, zeroed ID maps) must not
// reach the renderer, where it renders black without a single shader assert.
#include <string>

#include "bake/bake.h"

namespace shadel {

// "" if `baked` (already range-checked: sizes, indices, IDs) is what bakeMesh makes of `mesh`
// as far as can be told without baking again, else the first contradiction. Re-rasterises the
// baked UV triangles at every MIP level (linear in the ID maps' size) and requires:
//  - every shadel centre a triangle covers holds that triangle's ID (at MIP 0 except the at
//    most one shadel each force-assigned triangle took);
//  - the covered MIP-0 shadels match the recorded utilisation;
//  - every triangle but the recorded unowned ones owns a MIP-0 shadel.
std::string bakeContradictsMesh(const Mesh& mesh, const BakedMesh& baked);

} // namespace shadel
