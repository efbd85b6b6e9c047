#pragma once
// Capacity control (a global shading adjustment when storage nears its maximum): one global
// fractional MIP bias steered by last frame's storage counts. Raised at once when storage is near
// full or overflows, relaxed slowly (hysteresis) when there is room, so overflow lasts a few frames
// at most and the bias does not oscillate.
#include <cstdint>

namespace shadel {

struct CapacityController {
    float bias = 0.0f;        // added to the user's --shading-bias
    float high = 0.92f;       // raise above this fraction of storage requested
    float target = 0.8f;      // aim here when raising
    float low = 0.6f;         // relax only below this
    float relaxStep = 0.125f; // MIP levels per frame when relaxing
    float maxBias = 8.0f;
};

// Feeds one frame's counts: chunks requested (marked, including those that overflowed) and
// storage capacity in chunks. Returns the bias for the next frame.
float updateCapacityControl(CapacityController& c, uint64_t chunksRequested,
                            uint64_t chunksCapacity);

} // namespace shadel
