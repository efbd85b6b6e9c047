// 3-D debug lines a shader can emit (GPU-side debugging: shaders send lines to be
// drawn over the frame). debugLine appends one world-space segment to the frame's line buffer;
// render/debug/debug_lines.cpp draws them, depth-tested, before tonemapping. Off (address 0)
// unless --debug-lines asks for the kind. Segments beyond the buffer's capacity are counted and
// dropped (the stats report them).
#ifndef SHADEL_DEBUG_LINES_GLSL
#define SHADEL_DEBUG_LINES_GLSL
#include "common/bindless.glsl"
#include "common/ordered_float.glsl"

layout(buffer_reference, scalar) buffer DebugLinesRef {
    GpuDebugLines header;
    GpuDebugLine lines[];
};

bool debugLinesOn(FrameConstants f, uint kind) {
    return f.debugLines != 0ul && (DebugLinesRef(f.debugLines).header.mask & kind) != 0u;
}

void debugLine(FrameConstants f, vec3 a, vec3 b, vec3 color) {
    DebugLinesRef d = DebugLinesRef(f.debugLines);
    uint i = atomicAdd(d.header.count, 1u);
    if (i >= d.header.capacity) return;
    uint c = packUnorm4x8(vec4(clamp(color, 0.0, 1.0), 1.0));
    d.lines[i] = GpuDebugLine(a, c, b, c);
}

// A distinct colour per level (MIP): red, yellow, green, cyan, blue, magenta, then again.
vec3 debugLevelColour(uint level) {
    const vec3 palette[6] = vec3[6](vec3(1, 0.2, 0.2), vec3(1, 1, 0.2), vec3(0.2, 1, 0.2),
                                    vec3(0.2, 1, 1), vec3(0.3, 0.4, 1), vec3(1, 0.3, 1));
    return palette[level % 6u];
}

// The 12 edges of an axis-aligned box.
void debugBox(FrameConstants f, vec3 lo, vec3 hi, vec3 color) {
    for (int axis = 0; axis < 3; ++axis) {
        int u = (axis + 1) % 3, v = (axis + 2) % 3;
        for (int k = 0; k < 4; ++k) {
            vec3 a = lo;
            a[u] = (k & 1) != 0 ? hi[u] : lo[u];
            a[v] = (k & 2) != 0 ? hi[v] : lo[v];
            vec3 b = a;
            b[axis] = hi[axis];
            debugLine(f, a, b, color);
        }
    }
}

// A circle of `segments` segments in the plane spanned by the unit vectors u and v.
void debugCircle(FrameConstants f, vec3 centre, vec3 u, vec3 v, float radius, vec3 color,
                 uint segments) {
    const float TWO_PI = 6.28318530718;
    vec3 previous = centre + u * radius;
    for (uint i = 1u; i <= segments; ++i) {
        float angle = TWO_PI * float(i) / float(segments);
        vec3 next = centre + (u * cos(angle) + v * sin(angle)) * radius;
        debugLine(f, previous, next, color);
        previous = next;
    }
}

// Three great circles: a sphere's outline from any side.
void debugSphere(FrameConstants f, vec3 centre, float radius, vec3 color) {
    debugCircle(f, centre, vec3(1, 0, 0), vec3(0, 1, 0), radius, color, 24u);
    debugCircle(f, centre, vec3(0, 1, 0), vec3(0, 0, 1), radius, color, 24u);
    debugCircle(f, centre, vec3(0, 0, 1), vec3(1, 0, 0), radius, color, 24u);
}

// A rectangle from its centre and half axes.
void debugRect(FrameConstants f, vec3 centre, vec3 halfU, vec3 halfV, vec3 color) {
    vec3 c0 = centre - halfU - halfV, c1 = centre + halfU - halfV;
    vec3 c2 = centre + halfU + halfV, c3 = centre - halfU + halfV;
    debugLine(f, c0, c1, color);
    debugLine(f, c1, c2, color);
    debugLine(f, c2, c3, color);
    debugLine(f, c3, c0, color);
}

#ifdef DEBUG_LINES_WORKGROUP_BOX
// The world box of a compute workgroup's points (a shadel chunk's shaded positions): reduced in
// shared memory, the box emitted by one invocation. Call in uniform control flow; `valid`: this
// invocation contributes p. (Compute shaders define DEBUG_LINES_WORKGROUP_BOX to have it.)
shared uint sDebugBoxMin[3], sDebugBoxMax[3];
void debugWorkgroupBox(FrameConstants f, bool valid, vec3 p, vec3 color) {
    uint tid = gl_LocalInvocationIndex;
    if (tid < 3u) sDebugBoxMin[tid] = 0xFFFFFFFFu, sDebugBoxMax[tid] = 0u;
    barrier();
    if (valid)
        for (int a = 0; a < 3; ++a) {
            atomicMin(sDebugBoxMin[a], orderedFloatBits(p[a]));
            atomicMax(sDebugBoxMax[a], orderedFloatBits(p[a]));
        }
    barrier();
    if (tid == 0u && sDebugBoxMax[0] != 0u)
        debugBox(f,
                 vec3(orderedBitsFloat(sDebugBoxMin[0]), orderedBitsFloat(sDebugBoxMin[1]),
                      orderedBitsFloat(sDebugBoxMin[2])),
                 vec3(orderedBitsFloat(sDebugBoxMax[0]), orderedBitsFloat(sDebugBoxMax[1]),
                      orderedBitsFloat(sDebugBoxMax[2])),
                 color);
}
#endif
#endif
