#version 460
// LPV propagation, one thread per cell. Mode 0 (resolve) turns the injected fixed-point sums
// into the first propagation source, the accumulated radiance and the geometry volume. Mode 1
// gathers one step from the six neighbours [Kaplanyan and Dachsbacher 2010]: the flux each
// neighbour sends through the five faces of this cell it sees is re-emitted as a cosine lobe
// from each face, attenuated by the geometry volume's blocking potential between the two cells.
#include "common/bindless.glsl"
#extension GL_EXT_control_flow_attributes : require
#include "gi/gi_types.h"
#include "gi/sh.glsl"
#include "gi/blockers.glsl"

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(buffer_reference, scalar) readonly buffer GiInjectRef { int v[]; };
layout(buffer_reference, scalar) buffer GiShBuffer { vec4 c[]; };

layout(push_constant, scalar) uniform Push {
    uint64_t inject;   // int[GI_INJECT_INTS] per cell (mode 0)
    uint64_t source;   // vec4[3] per cell: last step's light (mode 1)
    uint64_t target;   // vec4[3] per cell: this step's light
    uint64_t accum;    // vec4[3] per cell: sum of every step (what the apply reads)
    uint64_t geometry; // vec4 per cell: blocking potential
    uint64_t axial;    // vec4 per cell: blocker coverage of its -x, -y, -z faces (xyz)
    uint64_t blockers; // GpuGiBlocker[blockerCount] (mode 0)
    uint64_t portals;  // vec4 per portal (mode 0)
    uint64_t cells;    // uint64 blocker mask per macro-cell, 0 = test every blocker (mode 0)
    vec3 origin;       // the cascade's min corner and cell size (mode 0)
    float cellSize;
    uint blockerCount;
    uint mode;
} pc;

// Axial occlusion of the face between cell - e_axis and cell: the fraction of four rays
// between the two cells (spread over the face) that a blocker stops.
float faceCoverage(ivec3 cell, int axis) {
    // The rays stay within one cell of this one: its macro-cell's blockers are all that can
    // cut them.
    uvec3 m = uvec3(cell) / GI_MACRO;
    uint64_t near = pc.cells == 0ul ? giAllBlockers(pc.blockerCount)
                                    : GiBlockerCells(pc.cells).m[(m.z * GI_MACRO_GRID + m.y) *
                                                                     GI_MACRO_GRID + m.x];
    if (near == 0ul) return 0.0;
    vec3 b = pc.origin + (vec3(cell) + 0.5) * pc.cellSize;
    vec3 e = vec3(0.0);
    e[axis] = pc.cellSize;
    vec3 u = vec3(0.0), v = vec3(0.0);
    u[(axis + 1) % 3] = 0.25 * pc.cellSize;
    v[(axis + 2) % 3] = 0.25 * pc.cellSize;
    float blocked = 0.0;
    for (int r = 0; r < 4; ++r) {
        vec3 offset = ((r & 1) == 0 ? -u : u) + ((r & 2) == 0 ? -v : v);
        if (giSegmentBlocked(pc.blockers, pc.portals, near, b - e + offset, b + offset))
            blocked += 0.25;
    }
    return blocked;
}

// Solid angles (over 4 pi... normalised by pi as in the reference implementation) a face of the
// neighbouring cell subtends from a cell's centre: the face straight ahead and a side face.
const float DIRECT_FACE = 0.4006696846 / 3.14159265358979;
const float SIDE_FACE = 0.4234413544 / 3.14159265358979;

uint cellIndex(ivec3 c) {
    return (uint(c.z) * GI_GRID + uint(c.y)) * GI_GRID + uint(c.x);
}

void main() {
    ivec3 cell = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(cell, ivec3(int(GI_GRID))))) return;
    uint index = cellIndex(cell);
    GiShBuffer target = GiShBuffer(pc.target);
    GiShBuffer accum = GiShBuffer(pc.accum);
    if (pc.mode == 0u) {
        GiInjectRef inject = GiInjectRef(pc.inject);
        uint base = index * GI_INJECT_INTS;
        for (uint ch = 0u; ch < 3u; ++ch) {
            vec4 v = vec4(inject.v[base + ch * 4u], inject.v[base + ch * 4u + 1u],
                          inject.v[base + ch * 4u + 2u], inject.v[base + ch * 4u + 3u]) /
                     float(GI_FIXED_SCALE);
            target.c[index * 3u + ch] = v;
            accum.c[index * 3u + ch] = v;
        }
        GiShBuffer(pc.geometry).c[index] =
            vec4(inject.v[base + 12u], inject.v[base + 13u], inject.v[base + 14u],
                 inject.v[base + 15u]) / float(GI_FIXED_SCALE);
        vec4 axial = vec4(0.0);
        if (pc.blockerCount > 0u)
            for (int axis = 0; axis < 3; ++axis) axial[axis] = faceCoverage(cell, axis);
        GiShBuffer(pc.axial).c[index] = axial;
        return;
    }
    GiShBuffer source = GiShBuffer(pc.source);
    GiShBuffer geometry = GiShBuffer(pc.geometry);
    vec4 here = geometry.c[index];
    vec4 axialHere = GiShBuffer(pc.axial).c[index];
    vec4 gathered[3] = vec4[3](vec4(0.0), vec4(0.0), vec4(0.0));
    // Unrolled, so every direction, face and lobe below is a compile-time constant.
    [[unroll]] for (int dir = 0; dir < 6; ++dir) {
        // Light travelling along d from the neighbour at cell - d into this cell.
        int axis = dir >> 1;
        ivec3 d = ivec3(0);
        d[axis] = (dir & 1) == 0 ? 1 : -1;
        ivec3 from = cell - d;
        if (any(lessThan(from, ivec3(0))) || any(greaterThanEqual(from, ivec3(int(GI_GRID)))))
            continue;
        uint fromIndex = cellIndex(from);
        vec4 src[3] = vec4[3](source.c[fromIndex * 3u], source.c[fromIndex * 3u + 1u],
                              source.c[fromIndex * 3u + 2u]);
        if (src[0] == vec4(0.0) && src[1] == vec4(0.0) && src[2] == vec4(0.0)) continue;
        // Surfaces facing the light (normal against d) between the two cells block it; the
        // mean of the two cells' blocking potential stands for the face between them.
        vec4 between = 0.5 * (here + geometry.c[fromIndex]);
        float transmit = 1.0 - clamp(dot(between, shBasis(-vec3(d))), 0.0, 1.0);
        // Blockers (axial occlusion): the face crossed is this cell's -axis face when d points
        // along +axis, else the neighbour's.
        float blocked = d[axis] > 0 ? axialHere[axis] : GiShBuffer(pc.axial).c[fromIndex][axis];
        transmit *= 1.0 - blocked;
        [[unroll]] for (int face = 0; face < 5; ++face) {
            vec3 evalDir, faceNormal;
            float solidAngle;
            if (face == 0) {
                evalDir = vec3(d);
                faceNormal = vec3(d);
                solidAngle = DIRECT_FACE;
            } else {
                // The four side faces: the two other axes, both signs.
                int other = (axis + 1 + ((face - 1) >> 1)) % 3;
                vec3 side = vec3(0.0);
                side[other] = ((face - 1) & 1) == 0 ? 1.0 : -1.0;
                evalDir = vec3(d) * 0.894427191 + side * 0.447213595; // normalize(d + side / 2)
                faceNormal = side;
                solidAngle = SIDE_FACE;
            }
            vec4 towardFace = shBasis(evalDir);
            vec4 reemit = shCosineLobe(faceNormal) * (solidAngle * transmit);
            for (int ch = 0; ch < 3; ++ch)
                gathered[ch] += max(dot(src[ch], towardFace), 0.0) * reemit;
        }
    }
    for (uint ch = 0u; ch < 3u; ++ch) {
        target.c[index * 3u + ch] = gathered[ch];
        accum.c[index * 3u + ch] += gathered[ch];
    }
}
