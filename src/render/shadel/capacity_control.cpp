#include "render/shadel/capacity_control.h"

#include <algorithm>
#include <cmath>

namespace shadel {

float updateCapacityControl(CapacityController& c, uint64_t chunksRequested,
                            uint64_t chunksCapacity) {
    if (chunksCapacity == 0) return c.bias;
    double use = double(chunksRequested) / double(chunksCapacity);
    if (use > c.high) {
        // Shadels scale with 4^-bias where the bias bites (one MIP = a quarter of the shadels),
        // so this step would bring use to the target. Where objects are magnified (their LOD
        // clamped at MIP 0) the bias bites later; a minimum step keeps it climbing until it does.
        float step = float(0.5 * std::log2(use / c.target));
        c.bias += std::max(step, 0.25f);
    } else if (use < c.low && c.bias > 0.0f) {
        // Relax only if one step down is predicted to stay under the high mark.
        if (use * std::pow(4.0, double(c.relaxStep)) < c.high)
            c.bias -= std::min(c.relaxStep, c.bias);
    }
    c.bias = std::clamp(c.bias, 0.0f, c.maxBias);
    return c.bias;
}

} // namespace shadel
