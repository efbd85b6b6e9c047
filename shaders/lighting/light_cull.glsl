// Culling tests shared by the forward tile pass (tile_cull.comp) and the shadel path's chunk
// culling (shaders/shadel/shade.comp): a light's bounding sphere (an area light's: its
// rectangle's plus its range), a spot's cone, its clip plane, an area light's back side, and
// the "shadow" volume a blocker casts from the light against a convex volume given by
// its 8 corners (a tile's depth-bounded frustum or a chunk's box). Every test is conservative:
// what culling removes contributes exactly nothing per pixel, so the image does not change.
#ifndef SHADEL_LIGHT_CULL_GLSL
#define SHADEL_LIGHT_CULL_GLSL
#include "common/lighting.glsl"
#include "common/spot_bounds.h"
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_vote : require

#define SHADOW_MISSES 0u  // the blocker's shadow does not reach the volume
#define SHADOW_PARTIAL 1u // part of the volume: test per pixel
#define SHADOW_COVERS 2u  // all of it, through no portal: the light is culled

// Corner i (bit 0: x, bit 1: y, bit 2: z; set: the high side) of the box lo..hi.
vec3 boxCorner(vec3 lo, vec3 hi, int i) {
    return vec3((i & 1) != 0 ? hi.x : lo.x, (i & 2) != 0 ? hi.y : lo.y, (i & 4) != 0 ? hi.z : lo.z);
}

// The sphere around everything the light reaches: xyz centre, w radius; w < 0 for lights
// without a finite range (never culled by distance). A spot's is the sphere around its lit
// sector (common/spot_bounds.h), far smaller than its range sphere for the usual narrow
// cones. Every culling test and the light grid (light_grid.cpp lightBoundingSphere, the same
// header) use it. On builtin:lights at 1280x720 (decoupled,
// spectra on) a chunk's grid candidates fell from 166 to 109 and its kept lights by 0.2%, the
// image unchanged; on lavapipe the culling passes' times did not move measurably (the tests
// are a small part of them).
vec4 lightSphere(GpuLight l) {
    if (l.type == LIGHT_DIRECTIONAL || l.range <= 0.0) return vec4(l.position, -1.0);
    float extra = l.type == LIGHT_TUBE ? l.halfLength : 0.0;
    if (l.type == LIGHT_AREA) extra = length(vec2(l.halfLength, l.radius)); // corner to centre
    float reach = l.range + extra;
    if (l.type == LIGHT_SPOT || l.type == LIGHT_SPOT_SQUARE)
        return spotSectorSphere(l.position, l.direction, reach,
                                spotConeCosSin(l.type, l.spotOffset, l.spotScale));
    return vec4(l.position, reach);
}

// Whether a sphere (a tile's or chunk's bounds) lies wholly outside a spot's outer cone (the
// square cone's circumscribed round one), or behind its apex: the closest point of the cone's
// surface to the centre is farther than the radius (Wronski's cone test). Gobos are spots.
bool spotConeMisses(GpuLight l, vec3 centre, float radius) {
    if (l.type != LIGHT_SPOT && l.type != LIGHT_SPOT_SQUARE) return false;
    vec2 cone = spotConeCosSin(l.type, l.spotOffset, l.spotScale);
    float c = cone.x, s = cone.y; // cosine and sine of the cone's half angle
    if (c <= 0.0) return false; // 90 degrees or wider: no cone to cull by
    vec3 v = centre - l.position;
    float along = dot(v, l.direction);
    float closest = c * sqrt(max(dot(v, v) - along * along, 0.0)) - along * s;
    return closest > radius || along < -radius;
}

// Whether a plane that bounds where the light shines leaves every corner unlit: its clip
// plane, or an area light's own plane (it emits toward `direction` only).
bool lightPlanesCull(GpuLight l, vec3 corners[8]) {
    if (l.type == LIGHT_AREA) {
        bool anyFront = false;
        for (int i = 0; i < 8; ++i)
            anyFront = anyFront || dot(l.direction, corners[i] - l.position) > 0.0;
        if (!anyFront) return true;
    }
    if ((l.flags & LIGHT_FLAG_CLIP_PLANE) == 0u) return false;
    for (int i = 0; i < 8; ++i)
        if (dot(l.clipPlane.xyz, corners[i]) + l.clipPlane.w >= 0.0) return false;
    return true;
}

// Whether the light's sphere meets the box. A spot's sphere (lightSphere) reaches past its range
// on the axis: the box must meet the range sphere around the apex too.
bool lightSphereMeetsBox(GpuLight light, vec4 sphere, vec3 boxMin, vec3 boxMax) {
    if (sphere.w < 0.0) return true;
    if (distance(clamp(sphere.xyz, boxMin, boxMax), sphere.xyz) > sphere.w) return false;
    if (light.type != LIGHT_SPOT && light.type != LIGHT_SPOT_SQUARE) return true;
    return distance(clamp(light.position, boxMin, boxMax), light.position) <= light.range;
}

// A shadel chunk's test of one light against its world box: the light's sphere meets the box,
// no bounding plane leaves every corner unlit, and a spot's cone meets the box's sphere.
bool chunkKeepsLight(GpuLight light, vec3 boxMin, vec3 boxMax, vec3 corners[8]) {
    bool keep = lightSphereMeetsBox(light, lightSphere(light), boxMin, boxMax);
    return keep && !lightPlanesCull(light, corners) &&
           !spotConeMisses(light, (boxMin + boxMax) * 0.5, 0.5 * distance(boxMin, boxMax));
}

// The shadow volume of the quad q0..q3 (in order around it) seen from lightPos: four planes
// through the light and each edge, and the quad's own plane (its far side), all facing inward.
// Returns SHADOW_MISSES when every corner is outside one plane, SHADOW_COVERS when all are
// inside every plane, SHADOW_PARTIAL otherwise.
uint quadShadowClass(vec3 lightPos, vec3 q[4], vec3 corners[8]) {
    vec3 centre = (q[0] + q[1] + q[2] + q[3]) * 0.25;
    vec3 quadNormal = cross(q[1] - q[0], q[3] - q[0]);
    float side = dot(quadNormal, centre - lightPos);
    if (abs(side) < 1e-6 * length(quadNormal)) return SHADOW_MISSES; // light in the plane
    vec4 planes[5];
    for (int e = 0; e < 4; ++e) {
        vec3 n = cross(q[e] - lightPos, q[(e + 1) & 3] - lightPos);
        if (dot(n, centre - lightPos) < 0.0) n = -n;
        planes[e] = vec4(n, -dot(n, lightPos));
    }
    vec3 away = side > 0.0 ? quadNormal : -quadNormal;
    planes[4] = vec4(away, -dot(away, centre));
    bool allInside = true;
    for (int p = 0; p < 5; ++p) {
        uint inside = 0u;
        for (int i = 0; i < 8; ++i) inside += dot(planes[p].xyz, corners[i]) + planes[p].w > 0.0 ? 1u : 0u;
        if (inside == 0u) return SHADOW_MISSES;
        allInside = allInside && inside == 8u;
    }
    return allInside ? SHADOW_COVERS : SHADOW_PARTIAL;
}

// A blocker's shadow from lightPos, holes included: covered only if no portal's own shadow
// volume (the light through the hole) reaches the volume.
uint blockerShadowClass(GpuLightBlocker b, LightPortalBuffer portals, vec3 lightPos, vec3 corners[8]) {
    vec3 u = b.axisU * b.halfU, v = b.axisV * b.halfV;
    vec3 q[4] = vec3[4](b.center - u - v, b.center + u - v, b.center + u + v, b.center - u + v);
    uint c = quadShadowClass(lightPos, q, corners);
    if (c != SHADOW_COVERS) return c;
    for (uint k = 0u; k < b.portalCount; ++k) {
        GpuLightPortal portal = portals.p[b.firstPortal + k];
        vec3 o = b.center;
        vec3 h[4] = vec3[4](o + b.axisU * portal.minUv.x + b.axisV * portal.minUv.y,
                            o + b.axisU * portal.maxUv.x + b.axisV * portal.minUv.y,
                            o + b.axisU * portal.maxUv.x + b.axisV * portal.maxUv.y,
                            o + b.axisU * portal.minUv.x + b.axisV * portal.maxUv.y);
        if (quadShadowClass(lightPos, h, corners) != SHADOW_MISSES) return SHADOW_PARTIAL;
    }
    return SHADOW_COVERS;
}

// The blockers of `light` against a volume given twice, both containing every point the light
// reaches in it: `corners` (a tile's frustum or a chunk's box) and the part of its bounding box
// [boxMin, boxMax] within the light's range (often far smaller for long tiles). A blocker
// misses if it misses either, covers if it covers either. Returns LIGHT_INVALID when one
// blocker hides the light from the whole volume, else the mask of those to test per pixel.
uint lightBlockerMask(LightingFrame lf, GpuLight light, vec3 corners[8], vec3 boxMin, vec3 boxMax) {
    if (lf.blockersOn == 0u || light.blockerCount == 0u) return 0u;
    vec4 sphere = lightSphere(light);
    vec3 inRange[8] = corners;
    if (sphere.w >= 0.0) {
        vec3 lo = max(boxMin, sphere.xyz - sphere.w), hi = min(boxMax, sphere.xyz + sphere.w);
        for (int i = 0; i < 8; ++i) inRange[i] = boxCorner(lo, hi, i);
    }
    LightBlockerBuffer blockers = LightBlockerBuffer(lf.blockers);
    LightPortalBuffer portals = LightPortalBuffer(lf.portals);
    UintBuffer list = UintBuffer(lf.lightBlockers);
    uint mask = 0u;
    uint n = min(light.blockerCount, LIGHT_MAX_BLOCKERS_PER_LIGHT);
    for (uint k = 0u; k < n; ++k) {
        GpuLightBlocker b = blockers.b[list.v[light.blockerFirst + k]];
        uint c = blockerShadowClass(b, portals, light.position, corners);
        if (c != SHADOW_MISSES && sphere.w >= 0.0) {
            uint c2 = blockerShadowClass(b, portals, light.position, inRange);
            c = c2 == SHADOW_MISSES ? SHADOW_MISSES : max(c, c2);
        }
        if (c == SHADOW_COVERS) return LIGHT_INVALID;
        if (c == SHADOW_PARTIAL) mask |= 1u << k;
    }
    return mask;
}

#include "common/ordered_float.glsl"

// The box of the positions of the subgroup's invocations with `inBox`, as order-preserving bits
// (hi.x == 0: none). Call where every invocation that needs the box is present.
void subgroupBoxBits(bool inBox, vec3 p, out uvec3 lo, out uvec3 hi) {
    uvec3 bits = orderedFloatBits(p);
    lo = subgroupMin(inBox ? bits : uvec3(0xFFFFFFFFu));
    hi = subgroupMax(inBox ? bits : uvec3(0u));
}

// The subgroup's lowest invocation whose writes land. In a fragment shader (the includer
// defines LIGHT_CULL_FRAGMENT) helper invocations take part in subgroup operations but their
// atomics are discarded, so one of them must not be the one that writes for the subgroup.
bool subgroupElectWriter() {
#ifdef LIGHT_CULL_FRAGMENT
    uvec4 writers = subgroupBallot(!gl_HelperInvocation);
    return subgroupBallotBitCount(writers) != 0u &&
           gl_SubgroupInvocationID == subgroupBallotFindLSB(writers);
#else
    return subgroupElect();
#endif
}

// With few lights (LightingFrame::subgroupLists: at most LIGHT_SUBGROUP_MAX_LIGHTS) each
// subgroup culls them for its own invocations, with no tile pass and no barrier: the box of the
// positions of its `shading` invocations against every light, kept in a bit set
// (LIGHT_LIST_SUBGROUP), so the loop runs in light order. A light a blocker hides from the whole
// box is dropped; a kept light with blockers tests each of them per pixel, as without culling.
// The sum is the one over every light: a light culled from the box adds nothing in it. Forward
// pixels and shadel chunks both use it. Why: on lavapipe a workgroup barrier suspends and
// resumes each subgroup, so a chunk's culling (three barriers, ~2.4 us) and the screen tile
// pass (50 ms at 1280x720) cost more than looping over builtin:default's 8 lights everywhere;
// this costs a few subgroup operations, and cut forward's shading by 18% and the shadels' by 25%
// there.
// Does nothing unless the frame chose it. Needs the subgroup ballot, vote and arithmetic
// extensions; in a fragment shader only the pixels being shaded take part, so the lights go
// round the present invocations (not the subgroup's width) and every shaded pixel must call it.
void useSubgroupLightList(FrameConstants f, bool shading, vec3 p) {
    if (f.lighting == 0ul) return;
    LightingFrame lf = LightingFrameRef(f.lighting).l;
    // The CPU chose it for at most that many lights; more would not fit the bit set (then the
    // loop over every light stays: the same sum).
    if (lf.subgroupLists == 0u || f.lightCount > LIGHT_SUBGROUP_MAX_LIGHTS) return;
    uvec3 lo, hi;
    subgroupBoxBits(shading, p, lo, hi);
    vec3 boxMin = orderedBitsFloat(lo), boxMax = orderedBitsFloat(hi);
    gLightListMode = LIGHT_LIST_SUBGROUP;
    gSubgroupLights = uvec2(0u);
    gSubgroupBlockerMask = lf.blockersOn != 0u ? 0xFFFFFFFFu : 0u;
    if (hi.x == 0u) return; // nothing to shade
    vec3 corners[8];
    for (int i = 0; i < 8; ++i) corners[i] = boxCorner(boxMin, boxMax, i);
    LightBuffer lights = LightBuffer(f.lights);
    uint lightCount = f.lightCount;
    uint culledByBlockers = 0u;
    bool perPixel = false;
    // Each present invocation tests one light a round; the kept ones land on their bits
    // through a subgroup OR.
    uvec4 present = subgroupBallot(true);
    uint lanes = subgroupBallotBitCount(present), rank = subgroupBallotExclusiveBitCount(present);
    bool blockers = lf.blockersOn != 0u;
    for (uint base = 0u; base < lightCount; base += lanes) {
        uint light = base + rank;
        bool near = light < lightCount && chunkKeepsLight(lights.l[light], boxMin, boxMax, corners);
        uint mask =
            near ? lightBlockerMask(lf, lights.l[light], corners, boxMin, boxMax) : LIGHT_INVALID;
        bool keep = mask != LIGHT_INVALID;
        gSubgroupLights |= subgroupOr(uvec2(keep && light < 32u ? 1u << light : 0u,
                                            keep && light >= 32u ? 1u << (light - 32u) : 0u));
        // Without blockers no light is culled by one nor needs a per-pixel test (keep == near,
        // mask 0), so these count nothing: skipped, they took 9 ms off 60 in a shadel shading
        // variant without material and lighting (builtin:default 1280x720).
        if (blockers) {
            culledByBlockers += subgroupBallotBitCount(subgroupBallot(near && !keep));
            perPixel = perPixel || subgroupAny(keep && mask != 0u);
        }
    }
    // lights_visible: one invocation marks the subgroup's kept lights, reading before the
    // atomic (most subgroups find the bits set already); per light and lane it took 5 ms more
    // in that variant.
    if (subgroupElectWriter()) {
        UintBuffer visible = UintBuffer(lf.visibleLights);
        for (uint w = 0u; w * 32u < lightCount; ++w) {
            uint kept = w == 0u ? gSubgroupLights.x : gSubgroupLights.y;
            if ((visible.v[w] & kept) != kept) atomicOr(visible.v[w], kept);
        }
    }
#ifdef LIGHT_CULL_SUBGROUP_COUNTS_CHUNKS
    // The shadel path's chunk statistics, a subgroup's list as the unit.
    if (subgroupElect()) {
        LightingCountersRef counters = LightingCountersRef(lf.counters);
        uint kept = uint(bitCount(gSubgroupLights.x) + bitCount(gSubgroupLights.y));
        atomicAdd(counters.c.lightSubgroupLists, 1u);
        if (kept != 0u) atomicAdd(counters.c.lightChunkPairs, kept);
        atomicAdd(counters.c.lightGridCandidates, lightCount);
        if (culledByBlockers != 0u) atomicAdd(counters.c.lightsCulledByBlockers, culledByBlockers);
        if (perPixel) atomicAdd(counters.c.perPixelBlockerChunks, 1u);
    }
#endif
}

#ifdef LIGHT_CULL_ORDERED_APPEND
// Compute only: appends the `keep` invocations' items in invocation order after the
// sAppendCount already placed and returns each keeper's slot (LIGHT_INVALID for the others).
// Keeping the lights' order makes culled shading sum exactly as unculled shading does. Call in
// uniform control flow.
shared uint sAppendCount;
shared uint sSubgroupCounts[256];
// This subgroup's first slot, given how many items it appends, after those already placed and
// those of the subgroups before it; sAppendCount then counts the whole workgroup's.
uint orderedAppendSubgroupBase(uint subgroupItems) {
    if (subgroupElect()) sSubgroupCounts[gl_SubgroupID] = subgroupItems;
    barrier();
    uint base = sAppendCount;
    for (uint s = 0u; s < gl_SubgroupID; ++s) base += sSubgroupCounts[s];
    uint total = 0u;
    if (gl_LocalInvocationIndex == 0u)
        for (uint s = 0u; s < gl_NumSubgroups; ++s) total += sSubgroupCounts[s];
    barrier();
    if (gl_LocalInvocationIndex == 0u) sAppendCount += total;
    barrier();
    return base;
}

uint orderedAppend(bool keep) {
    uvec4 ballot = subgroupBallot(keep);
    uint base = orderedAppendSubgroupBase(subgroupBallotBitCount(ballot));
    return keep ? base + subgroupBallotExclusiveBitCount(ballot) : LIGHT_INVALID;
}
#endif

// Heat colour of a light count (--visualize light-count): black, blue, green, yellow, red, white.
vec3 lightCountHeat(uint n) {
    const vec3 ramp[6] = vec3[6](vec3(0.0), vec3(0.0, 0.2, 1.0), vec3(0.0, 0.9, 0.2),
                                 vec3(1.0, 0.9, 0.0), vec3(1.0, 0.1, 0.0), vec3(1.0));
    float t = clamp(log2(float(n) + 1.0) / 1.5, 0.0, 4.999); // 0, 1.8, 5, 12, 36, 180 lights
    int i = int(t);
    return mix(ramp[i], ramp[i + 1], fract(t));
}
#endif
