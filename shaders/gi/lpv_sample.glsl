// Apply of the light propagation volume: the indirect irradiance at a surface point, read from
// the first volume that holds it: an artist's local volume, else the finest camera cascade
// (shared by forward and decoupled shading via lighting.glsl).
#ifndef SHADEL_GI_LPV_SAMPLE_GLSL
#define SHADEL_GI_LPV_SAMPLE_GLSL
#include "common/bindless.glsl"
#include "gi/gi_types.h"
#include "gi/sh.glsl"
#include "gi/blockers.glsl"

layout(buffer_reference, scalar) readonly buffer GiFrameRef { GiFrame g; };
layout(buffer_reference, scalar) readonly buffer GiRadianceBuffer { vec4 c[]; };
// Irradiance arriving at a surface with normal n from one cascade, trilinear over cells.
vec3 giCascadeIrradiance(GiFrame g, GiCascade c, vec3 p, vec3 n) {
    GiRadianceBuffer radiance = GiRadianceBuffer(c.radiance);
    vec3 q = (p - c.origin) / c.cellSize - 0.5; // cell centres at integer coordinates
    ivec3 i0 = ivec3(floor(q));
    vec3 t = q - vec3(i0);
    // Light arriving at the surface travels along -n: the receiver's cosine lobe faces -n.
    vec4 lobe = shCosineLobe(-n);
    vec3 sum = vec3(0.0);
    float kept = 0.0;
    // Blockers culled per macro-cell (4x4x4 cells each): most cells test none.
    uint64_t near = g.blockerCount > 0u ? giBlockersNear(g, c, p) : 0ul;
    for (int k = 0; k < 8; ++k) {
        ivec3 o = ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
        ivec3 cell = clamp(i0 + o, ivec3(0), ivec3(int(GI_GRID) - 1));
        vec3 w3 = mix(1.0 - t, t, vec3(o));
        float w = w3.x * w3.y * w3.z;
        // A tap whose cell centre is behind a blocker holds light from the blocker's other side.
        if (near != 0ul && giSegmentBlocked(g.blockers, g.portals, near, p,
                                            c.origin + (vec3(cell) + 0.5) * c.cellSize))
            continue;
        kept += w;
        uint index = (uint(cell.z) * GI_GRID + uint(cell.y)) * GI_GRID + uint(cell.x);
        sum += w * vec3(dot(radiance.c[index * 3u + 0u], lobe),
                        dot(radiance.c[index * 3u + 1u], lobe),
                        dot(radiance.c[index * 3u + 2u], lobe));
    }
    // Taps behind a blocker drop out; the rest are renormalised (none left: no light).
    if (kept <= 0.0) return vec3(0.0);
    sum /= kept;
    // The volume stores radiant intensity per cell; over the cell's cross-section it is radiance.
    return max(sum, vec3(0.0)) / (c.cellSize * c.cellSize);
}

// Where p sits in cascade c: 0 outside, rising to 1 two cells in from the border (blend band).
float giCascadeWeight(GiCascade c, vec3 p) {
    vec3 q = (p - c.origin) / c.cellSize;
    vec3 border = min(q, vec3(float(GI_GRID)) - q);
    return clamp((min(border.x, min(border.y, border.z)) - 1.0) / 2.0, 0.0, 1.0);
}

// Indirect irradiance at p (normal n); 0 when GI is off or p lies outside every cascade. Local
// volumes, then finer cascades win; a point in a volume's border band blends into the next one.
vec3 giIrradiance(uint64_t giFrame, vec3 p, vec3 n) {
    if (giFrame == 0ul) return vec3(0.0);
    GiFrame g = GiFrameRef(giFrame).g;
    vec3 result = vec3(0.0);
    float remaining = 1.0;
    for (uint i = 0u; i < g.cascadeCount && remaining > 0.0; ++i) {
        GiCascade c = g.cascades[i];
        // Sample half a cell in front of the surface: the cell behind a wall holds light that
        // never reaches its front (the classic LPV leak).
        vec3 sp = p + n * (0.5 * c.cellSize);
        float w = giCascadeWeight(c, sp) * remaining;
        if (i + 1u == g.cascadeCount && w > 0.0) w = remaining; // the coarsest takes the rest
        if (w <= 0.0) continue;
        result += w * giCascadeIrradiance(g, c, sp, n);
        remaining -= w;
    }
    return result * g.intensity;
}
#endif
