#pragma once
// The virtual sheet's CPU allocation: each decoupled object's level rects, placed in the
// column of blocks of their MIP level, holding a window of the level (the blocks last frame's
// samples wanted there). prepareDecoupledFrame decides, per object, the finest level it needs.
#include <cstdint>

#include <glm/glm.hpp>

#include "render/shadel/decoupled_state.h"

namespace shadel {

struct Gpu;
struct ShadelMeshInfo;

// A level's size in blocks.
glm::uvec2 levelBlocks(const ShadelMeshInfo& mesh, uint32_t k);

// Gives back every level rect of the object.
void freeObject(Gpu& gpu, DecoupledState& d, ObjectSlot& o);

// Coarse CPU allocation (the CPU's estimate of the space an object can need): a potentially
// visible object gets rects from the finest MIP it can need this frame down to its coarsest;
// objects that leave the view give theirs back. Levels are added as the camera comes closer and
// dropped (with one level of slack, so a camera hovering at a boundary does not churn the sheet) as
// it moves away. Returns false when the object has no rects at all (drawn forward this frame).
bool updateObjectRects(Gpu& gpu, DecoupledState& d, ObjectSlot& o, uint32_t object,
                       const ShadelMeshInfo& mesh, uint32_t wantFirst, bool wasDecoupled,
                       bool& limited);

} // namespace shadel
