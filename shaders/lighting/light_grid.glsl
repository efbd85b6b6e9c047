// The light grid query of a shadel chunk's light culling (render/lighting/light_grid.h; the
// layout is common/shared_types.h GpuLightGrid). The candidates (the global list, the level's
// big list and the buckets of the at most 2x2x2 cells the box meets) are tested exactly as
// without the grid, kept ones set in a shared bit set (a light listed in several buckets
// counts once), and the bit set is compacted in light order, so the list is the one the loop
// over every light would have built. Needs light_cull.glsl (orderedAppend's sAppendCount, which
// the compaction sets); the includer defines LIGHT_GRID_LIST and LIGHT_GRID_LIST_MAX (the shared
// list the compaction fills). Call in uniform control flow. Without LIGHT_GRID_LIST only the
// query (per invocation, no shared memory: lighting/chunk_classify.comp).
#ifndef SHADEL_LIGHT_GRID_GLSL
#define SHADEL_LIGHT_GRID_GLSL

// A box's grid query: its level and cells. Sources: 0 the global list, 1 the level's big
// list, 2.. the cells (x fastest).
struct LightGridQuery {
    GpuLightGrid g;
    uint level;
    ivec3 lo;
    ivec3 cells;
};

// Whether the grid can answer at all: there is one, and the bit set holds every light.
bool lightGridUsable(FrameConstants f, uint64_t gridAddress) {
    return gridAddress != 0ul && f.lightCount <= LIGHT_GRID_MASK_LIGHTS;
}

// False when the grid cannot answer: not usable, or the box is larger than its coarsest cell
// (the caller then tests every light).
bool lightGridQuery(FrameConstants f, uint64_t gridAddress, vec3 boxMin, vec3 boxMax,
                    out LightGridQuery q) {
    if (!lightGridUsable(f, gridAddress)) return false;
    q.g = LightGridRef(gridAddress).g;
    vec3 size = boxMax - boxMin;
    float extent = max(size.x, max(size.y, size.z));
    q.level = 0u;
    float cell = q.g.cellSize;
    while (q.level < q.g.levels && cell < extent) {
        cell *= 2.0;
        q.level++;
    }
    if (q.level >= q.g.levels) return false;
    vec3 a = floor((boxMin - q.g.origin) / cell), b = floor((boxMax - q.g.origin) / cell);
    if (any(greaterThanEqual(abs(a), vec3(LIGHT_GRID_MAX_CELL))) ||
        any(greaterThanEqual(abs(b), vec3(LIGHT_GRID_MAX_CELL))))
        return false;
    q.lo = ivec3(a);
    q.cells = ivec3(b) - q.lo + 1;
    return true;
}

uint lightGridSources(LightGridQuery q) {
    return 2u + uint(q.cells.x * q.cells.y * q.cells.z);
}

// (first entry, count) of one source's light indices in q.g.entries.
uvec2 lightGridSource(LightGridQuery q, uint source) {
    if (source == 0u) return uvec2(q.g.globalFirst, q.g.globalCount);
    if (source == 1u) return q.g.big[q.level];
    int c = int(source) - 2;
    ivec3 at = q.lo + ivec3(c % q.cells.x, (c / q.cells.x) % q.cells.y, c / (q.cells.x * q.cells.y));
    return LightGridBuckets(q.g.buckets).b[q.level * LIGHT_GRID_BUCKETS + LIGHT_GRID_HASH(at.x, at.y, at.z)];
}

// The query's candidates as one range: each source's (first entry, count) and their total, so
// a workgroup takes its candidates `threads` at a time however they spread over the sources
// (a loop per source left most invocations idle on the small buckets: on builtin:lights at
// 1280x720, ~100 candidates a chunk over up to 10 sources). At most 2 + 2x2x2 sources: the
// level's cells are at least the box's size.
#define LIGHT_GRID_MAX_SOURCES 10u
struct LightGridCandidates {
    uvec2 lists[LIGHT_GRID_MAX_SOURCES];
    uint sources;
    uint total;
    uint64_t entries; // the grid's entries; 0: one source holding every light (lightCandidatesNear)
};

LightGridCandidates lightGridCandidates(LightGridQuery q) {
    LightGridCandidates c;
    c.sources = min(lightGridSources(q), LIGHT_GRID_MAX_SOURCES);
    c.total = 0u;
    for (uint s = 0u; s < LIGHT_GRID_MAX_SOURCES; ++s) {
        c.lists[s] = s < c.sources ? lightGridSource(q, s) : uvec2(0u);
        c.total += c.lists[s].y;
    }
    c.entries = q.g.entries;
    return c;
}

// The candidates near a box, or every light as one source when the grid cannot answer (no grid,
// or a box larger than its cells): what one invocation walks for a chunk.
LightGridCandidates lightCandidatesNear(FrameConstants f, uint64_t gridAddress, vec3 boxMin,
                                        vec3 boxMax) {
    LightGridQuery q;
    if (lightGridQuery(f, gridAddress, boxMin, boxMax, q)) return lightGridCandidates(q);
    LightGridCandidates c;
    for (uint s = 0u; s < LIGHT_GRID_MAX_SOURCES; ++s) c.lists[s] = uvec2(0u);
    c.lists[0] = uvec2(0u, f.lightCount);
    c.sources = 1u;
    c.total = f.lightCount;
    c.entries = 0ul;
    return c;
}

// The light of candidate k of source s.
uint lightCandidate(LightGridCandidates c, uint s, uint k) {
    return c.entries != 0ul ? LightGridEntries(c.entries).v[c.lists[s].x + k] : k;
}

// Where candidate k (< c.total) sits in the grid's entries.
uint lightGridCandidateEntry(LightGridCandidates c, uint k) {
    for (uint s = 0u; s < LIGHT_GRID_MAX_SOURCES; ++s) {
        if (k < c.lists[s].y) return c.lists[s].x + k;
        k -= c.lists[s].y;
    }
    return 0u; // not reached for k < c.total
}

#ifdef LIGHT_GRID_LIST // a workgroup's query, through a shared bit set
shared uint sGridMask[LIGHT_GRID_MASK_LIGHTS / 32u];
shared uint sGridCandidates;

// Clears the bit set when the grid is usable; the caller's next barrier makes it visible (tile
// culling and a chunk's shading clear it under a barrier they need anyway).
void lightGridMaskClearUnsynced(FrameConstants f, uint64_t gridAddress, uint threads) {
    if (!lightGridUsable(f, gridAddress)) return;
    for (uint w = gl_LocalInvocationIndex; w < (f.lightCount + 31u) / 32u; w += threads) sGridMask[w] = 0u;
    if (gl_LocalInvocationIndex == 0u) sGridCandidates = 0u;
}

// The kept lights of the bit set, in light order, into LIGHT_GRID_LIST (a shared uvec2 array of
// LIGHT_GRID_LIST_MAX entries the includer names) from its start; their count (entries past the
// array's end are counted, not written) goes to orderedAppend's sAppendCount. One invocation
// walks the set: a box keeps a few of its candidates (~7 of ~100 per chunk on builtin:lights)
// and walking lightCount / 32 words costs less than a parallel compaction's subgroup scans and
// barriers (on lavapipe, where a workgroup's invocations run in turn, 2.4 us a chunk). Barrier
// before reading the list or the count.
void lightGridMaskCompact(uint lightCount) {
    if (gl_LocalInvocationIndex != 0u) return;
    uint placed = 0u;
    for (uint w = 0u; w < (lightCount + 31u) / 32u; ++w) {
        uint word = sGridMask[w];
        while (word != 0u) {
            uint bit = uint(findLSB(word));
            if (placed < LIGHT_GRID_LIST_MAX) LIGHT_GRID_LIST[placed] = uvec2(w * 32u + bit, 0u);
            placed++;
            word &= word - 1u;
        }
    }
    sAppendCount = placed;
}

// A shadel chunk's lights: those chunkKeepsLight keeps, as the loop over every light in
// shade.comp tests them. The caller cleared the bit set (lightGridMaskClearUnsynced, then a
// barrier) and barriers before reading the list and its count (sAppendCount).
bool gridChunkLights(FrameConstants f, uint64_t gridAddress, vec3 boxMin, vec3 boxMax,
                     vec3 corners[8], uint threads) {
    LightGridQuery q;
    if (!lightGridQuery(f, gridAddress, boxMin, boxMax, q)) return false;
    LightBuffer lights = LightBuffer(f.lights);
    UintBuffer entries = UintBuffer(q.g.entries);
    uint tested = 0u;
    LightGridCandidates candidates = lightGridCandidates(q);
    for (uint k = gl_LocalInvocationIndex; k < candidates.total; k += threads) {
        uint index = entries.v[lightGridCandidateEntry(candidates, k)];
        if (chunkKeepsLight(lights.l[index], boxMin, boxMax, corners)) atomicOr(sGridMask[index >> 5], 1u << (index & 31u));
        tested++;
    }
    if (tested != 0u) atomicAdd(sGridCandidates, tested);
    barrier();
    lightGridMaskCompact(f.lightCount);
    return true;
}

#endif // LIGHT_GRID_LIST

#endif
