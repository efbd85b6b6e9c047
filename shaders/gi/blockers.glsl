// GI light blockers (render/gi/lpv.h GiBlocker): rectangles light does not cross.
#ifndef SHADEL_GI_BLOCKERS_GLSL
#define SHADEL_GI_BLOCKERS_GLSL
#include "common/bindless.glsl"
#include "gi/gi_types.h"

layout(buffer_reference, scalar) readonly buffer GiBlockerList { GpuGiBlocker b[]; };

// Whether the segment a -> b crosses one of the blockers.
bool giSegmentBlocked(uint64_t blockers, uint count, vec3 a, vec3 b) {
    GiBlockerList list = GiBlockerList(blockers);
    for (uint k = 0u; k < count; ++k) {
        GpuGiBlocker r = list.b[k];
        vec3 n = cross(r.axisU, r.axisV);
        float da = dot(a - r.center, n), db = dot(b - r.center, n);
        if ((da > 0.0) == (db > 0.0)) continue;
        vec3 hit = mix(a, b, da / (da - db)) - r.center;
        if (abs(dot(hit, r.axisU)) <= r.halfU && abs(dot(hit, r.axisV)) <= r.halfV) return true;
    }
    return false;
}
#endif
