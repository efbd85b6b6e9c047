// GI light blockers (render/gi/lpv.h GiBlocker): rectangles light does not cross, except
// through their portals.
#ifndef SHADEL_GI_BLOCKERS_GLSL
#define SHADEL_GI_BLOCKERS_GLSL
#include "common/bindless.glsl"
#include "gi/gi_types.h"

layout(buffer_reference, scalar) readonly buffer GiBlockerList { GpuGiBlocker b[]; };
layout(buffer_reference, scalar) readonly buffer GiPortalList { vec4 p[]; };
layout(buffer_reference, scalar) readonly buffer GiBlockerCells { uint64_t m[]; };

// Whether the segment a -> b crosses blocker r outside its portals.
bool giBlockerStops(GpuGiBlocker r, uint64_t portals, vec3 a, vec3 b) {
    vec3 n = cross(r.axisU, r.axisV);
    float da = dot(a - r.center, n), db = dot(b - r.center, n);
    if ((da > 0.0) == (db > 0.0)) return false;
    vec3 hit = mix(a, b, da / (da - db)) - r.center;
    vec2 uv = vec2(dot(hit, r.axisU), dot(hit, r.axisV));
    if (abs(uv.x) > r.halfU || abs(uv.y) > r.halfV) return false;
    uint count = r.portals >> 16;
    GiPortalList list = GiPortalList(portals);
    for (uint i = 0u; i < count; ++i) {
        vec4 q = list.p[(r.portals & 0xFFFFu) + i];
        if (all(greaterThanEqual(uv, q.xy)) && all(lessThanEqual(uv, q.zw))) return false;
    }
    return true;
}

// Whether the segment a -> b crosses one of the blockers in `mask` (bit k: blocker k).
bool giSegmentBlocked(uint64_t blockers, uint64_t portals, uint64_t mask, vec3 a, vec3 b) {
    GiBlockerList list = GiBlockerList(blockers);
    uvec2 bits = uvec2(uint(mask), uint(mask >> 32));
    for (uint word = 0u; word < 2u; ++word) {
        uint m = bits[word];
        while (m != 0u) {
            uint k = uint(findLSB(m));
            m &= m - 1u;
            if (giBlockerStops(list.b[word * 32u + k], portals, a, b)) return true;
        }
    }
    return false;
}

// Every blocker of `count` as a mask.
uint64_t giAllBlockers(uint count) {
    return count >= 64u ? ~0ul : (1ul << count) - 1ul;
}

// The blockers that can cut a segment from p to within one cell of it in cascade c: p's
// macro-cell's list, or every blocker outside the grid (or with --gi-blocker-cells off).
uint64_t giBlockersNear(GiFrame g, GiCascade c, vec3 p) {
    ivec3 m = ivec3(floor((p - c.origin) / (c.cellSize * float(GI_MACRO))));
    if (g.blockerCells == 0u || c.blockerCells == 0ul || any(lessThan(m, ivec3(0))) ||
        any(greaterThanEqual(m, ivec3(int(GI_MACRO_GRID)))))
        return giAllBlockers(g.blockerCount);
    uint index = (uint(m.z) * GI_MACRO_GRID + uint(m.y)) * GI_MACRO_GRID + uint(m.x);
    return GiBlockerCells(c.blockerCells).m[index];
}
#endif
