#version 460
// LPV injection: every reflective-shadow-map texel is a virtual point light. Its reflected
// intensity (a cosine lobe about its normal, flux / pi) goes into the cell half a cell in front
// of the surface in every cascade; its area, as blocking potential, into the geometry volume.
#include "common/bindless.glsl"
#include "gi/gi_types.h"
#include "gi/sh.glsl"
#include "gi/blockers.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(buffer_reference, scalar) readonly buffer GiFrameRef { GiFrame g; };
layout(buffer_reference, scalar) buffer GiInjectBuffer { int v[]; };

layout(push_constant, scalar) uniform Push {
    uint64_t gi;                   // GiFrame
    uint64_t inject[GI_MAX_VOLUMES]; // int[GI_INJECT_INTS] per cell, per volume
    uint positionSlot;
    uint normalSlot;
    uint fluxSlot;
    uint size; // RSM texels per side
    uint cascadeMask; // bit c: volume c is (re)injected this frame
} pc;

void addFixed(GiInjectBuffer b, uint index, float value) {
    // Clamped so a pathological cell saturates instead of wrapping around.
    int fixedValue = int(clamp(value * GI_FIXED_SCALE, -1.0e9, 1.0e9));
    if (fixedValue != 0) atomicAdd(b.v[index], fixedValue);
}

bool cellOf(GiFrame g, GiCascade c, vec3 p, out uint index) {
    ivec3 cell = ivec3(floor((p - c.origin) / c.cellSize));
    index = 0u;
    if (any(lessThan(cell, ivec3(0))) || any(greaterThanEqual(cell, ivec3(int(GI_GRID)))))
        return false;
    // A point whose cell centre lies behind a blocker would put its light on the other side.
    if (g.blockerCount > 0u && giSegmentBlocked(g.blockers, g.portals, giBlockersNear(g, c, p), p,
                                                c.origin + (vec3(cell) + 0.5) * c.cellSize))
        return false;
    index = (uint(cell.z) * GI_GRID + uint(cell.y)) * GI_GRID + uint(cell.x);
    return true;
}

void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(texel, ivec2(int(pc.size))))) return;
    vec4 position = fetchTextureUniform(pc.positionSlot, texel, 0);
    if (position.w == 0.0) return; // no surface
    vec4 normal = fetchTextureUniform(pc.normalSlot, texel, 0);
    vec3 flux = fetchTextureUniform(pc.fluxSlot, texel, 0).rgb;
    vec3 n = normalize(normal.xyz);
    vec4 lobe = shCosineLobe(n);
    vec4 intensity[3] = vec4[3](lobe * (flux.r / PI_GI), lobe * (flux.g / PI_GI),
                                lobe * (flux.b / PI_GI));
    GiFrame g = GiFrameRef(pc.gi).g;
    for (uint i = 0u; i < g.cascadeCount; ++i) {
        if ((pc.cascadeMask & (1u << i)) == 0u) continue;
        GiCascade c = g.cascades[i];
        GiInjectBuffer b = GiInjectBuffer(pc.inject[i]);
        uint cell;
        if (dot(flux, flux) > 0.0 && cellOf(g, c, position.xyz + n * (0.5 * c.cellSize), cell)) {
            for (uint ch = 0u; ch < 3u; ++ch)
                for (uint k = 0u; k < 4u; ++k)
                    addFixed(b, cell * GI_INJECT_INTS + ch * 4u + k, intensity[ch][k]);
        }
        // Blocking potential: the fraction of the cell's cross-section the surface covers.
        if (cellOf(g, c, position.xyz, cell)) {
            float coverage = clamp(normal.w / (c.cellSize * c.cellSize), 0.0, 1.0);
            for (uint k = 0u; k < 4u; ++k)
                addFixed(b, cell * GI_INJECT_INTS + 12u + k, lobe[k] * coverage);
        }
    }
}
