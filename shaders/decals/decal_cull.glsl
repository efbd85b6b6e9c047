// Decal culling of the screen-tile workgroups of the decal culling pass
// (render/decals/decals.h): a decal's box against a convex volume, an ordered append (lists keep
// the decals' order, so overlapping decals combine the same way in every tile), and writing one
// list per decal stage into the shared pool.
#ifndef SHADEL_DECAL_CULL_GLSL
#define SHADEL_DECAL_CULL_GLSL
#extension GL_KHR_shader_subgroup_ballot : require
#include "common/material.glsl" // which includes decals/decals.glsl

// The decal's box is not wholly outside any of the planes (inside: dot(n, x) + w >= 0).
bool decalInsidePlanes(GpuDecal d, vec4 planes[6]) {
    for (int p = 0; p < 6; ++p) {
        vec3 n = planes[p].xyz;
        float reach = abs(dot(n, d.axisX)) * d.halfSize.x + abs(dot(n, d.axisY)) * d.halfSize.y +
                      abs(dot(n, d.axisZ)) * d.halfSize.z;
        if (dot(n, d.center) + planes[p].w < -reach) return false;
    }
    return true;
}

shared uint sDecalCount;
shared uint sDecalSubgroupCounts[256];
shared uint sDecalList[DECAL_TILE_MAX];

// Each invocation offers one decal; keepers get consecutive places after those placed before,
// in invocation order. Call in uniform control flow.
void decalOrderedAppend(bool keep, uint decal) {
    uvec4 ballot = subgroupBallot(keep);
    uint within = subgroupBallotExclusiveBitCount(ballot);
    if (subgroupElect()) sDecalSubgroupCounts[gl_SubgroupID] = subgroupBallotBitCount(ballot);
    barrier();
    uint base = sDecalCount;
    for (uint s = 0u; s < gl_SubgroupID; ++s) base += sDecalSubgroupCounts[s];
    uint total = 0u;
    if (gl_LocalInvocationIndex == 0u)
        for (uint s = 0u; s < gl_NumSubgroups; ++s) total += sDecalSubgroupCounts[s];
    if (keep && base + within < DECAL_TILE_MAX) sDecalList[base + within] = decal;
    barrier();
    if (gl_LocalInvocationIndex == 0u) sDecalCount += total;
    barrier();
}

// Every decal of the index list at `list` (`count` entries, in decal order) meeting the volume
// `meets` tests, 'threads' at a time, into sDecalList.
#define DECAL_CULL_LIST_LOOP(df, list, count, threads, meets)                                     \
    {                                                                                             \
        DecalBuffer decalsIn = DecalBuffer(df.decals);                                            \
        UintBuffer listIn = UintBuffer(list);                                                     \
        uint listCount = (count);                                                                 \
        for (uint base = 0u; base < listCount; base += threads) {                                 \
            uint i = base + gl_LocalInvocationIndex;                                              \
            uint index = i < listCount ? listIn.v[i] : 0u;                                        \
            bool keep = false;                                                                    \
            if (i < listCount) {                                                                  \
                GpuDecal d = decalsIn.d[index];                                                   \
                keep = meets;                                                                     \
            }                                                                                     \
            decalOrderedAppend(keep, index);                                                      \
        }                                                                                         \
    }

// Every decal meeting the camera frustum that `meets`.
#define DECAL_CULL_LOOP(df, threads, meets)                                                       \
    DECAL_CULL_LIST_LOOP(df, df.frustumDecals, df.frustumDecalCount, threads, meets)

// The lists of one tile (`ranges` + `index`), one per stage, from sDecalList. Call in uniform
// control flow after the loop.
void writeDecalLists(DecalFrame df, uint64_t ranges, uint index, uint threads) {
    uint tid = gl_LocalInvocationIndex;
    uint count = min(sDecalCount, DECAL_TILE_MAX);
    DecalBuffer decals = DecalBuffer(df.decals);
    DecalCountersRef counters = DecalCountersRef(df.counters);
    if (tid < DECAL_STAGES) {
        uint st = tid, n = 0u;
        for (uint i = 0u; i < count; ++i)
            n += (decals.d[sDecalList[i]].kinds & DECAL_KIND(st)) != 0u ? 1u : 0u;
        uint first = n > 0u ? atomicAdd(counters.c.poolEntries, n) : 0u;
        bool fits = first + n <= df.poolCapacity;
        if (!fits) atomicAdd(counters.c.listsOverflowed, 1u);
        UintBuffer entries = UintBuffer(df.entries);
        uint w = 0u;
        if (fits)
            for (uint i = 0u; i < count; ++i)
                if ((decals.d[sDecalList[i]].kinds & DECAL_KIND(st)) != 0u)
                    entries.v[first + w++] = sDecalList[i];
        DecalRangeBuffer(ranges).r[index * DECAL_STAGES + st] = uvec2(first, fits ? n : 0u);
    }
    if (tid == 0u) {
        atomicAdd(counters.c.tilePairs, count);
        if (sDecalCount > DECAL_TILE_MAX) atomicAdd(counters.c.listsOverflowed, 1u);
    }
    for (uint i = tid; i < count; i += threads)
        atomicOr(UintBuffer(df.visibleDecals).v[sDecalList[i] >> 5], 1u << (sDecalList[i] & 31u));
}

void clearDecalLists(uint64_t ranges, uint index) {
    if (gl_LocalInvocationIndex < DECAL_STAGES)
        DecalRangeBuffer(ranges).r[index * DECAL_STAGES + gl_LocalInvocationIndex] = uvec2(0u);
}
#endif
