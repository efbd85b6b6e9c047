// Projected box decals (render/decals): applied to the material before
// lighting, in the material code both paths share (evaluateMaterial, common/material.glsl, calls
// applyDecals last). The caller picks the list first, as it does for lights: forward shading the
// list of its pixel's 16x16 tile (useTileDecalList, built by the culling pass,
// decals/tile_cull.comp), shadel shading the list of its object (the culling pass's,
// object_cull.comp) narrowed to the shadel's own point in registers (useShadelDecalList, called
// by shadel/shade.comp). Without a list (every other caller of
// evaluateMaterial: transparency, ray hits, RSMs) nothing is applied.
//
// So in the shadel path a decal is evaluated once per shadel, at the shadel's surface point, and
// reused by every pixel (and frame) that reads the shadel, like the rest of the material.
//
// Stages run in order (base colour, normal, roughness, ambient occlusion; DECAL_STAGE_*), each
// over its own list (or mask) in decal order, so overlapping decals combine the same way everywhere.
#ifndef SHADEL_DECALS_GLSL
#define SHADEL_DECALS_GLSL
// Included by common/material.glsl (after MaterialSample), not on its own.
#include "common/bindless.glsl"

layout(buffer_reference, scalar) readonly buffer DecalFrameRef { DecalFrame d; };
layout(buffer_reference, scalar) readonly buffer DecalBuffer { GpuDecal d[]; };
layout(buffer_reference, scalar) buffer DecalRangeBuffer { uvec2 r[]; };
layout(buffer_reference, scalar) buffer DecalCountersRef { DecalCounters c; };

uint64_t gDecals = 0ul;       // GpuDecal[] of the chosen list; 0: no decals for this surface
uint64_t gDecalEntries = 0ul; // the pool of decal indices
uvec2 gDecalRanges[DECAL_STAGES];

// The decal's box meets the axis-aligned box [lo, hi]: separating axes of both boxes' faces
// (conservative: the edge-cross axes are not tested, so a few near misses are kept).
bool decalMeetsBox(GpuDecal d, vec3 lo, vec3 hi) {
    vec3 axes[3] = vec3[3](d.axisX, d.axisY, d.axisZ);
    vec3 reach = abs(axes[0]) * d.halfSize.x + abs(axes[1]) * d.halfSize.y + abs(axes[2]) * d.halfSize.z;
    if (any(greaterThan(d.center - reach, hi)) || any(lessThan(d.center + reach, lo))) return false;
    vec3 c = (lo + hi) * 0.5, e = (hi - lo) * 0.5;
    for (int a = 0; a < 3; ++a) {
        float boxReach = dot(abs(axes[a]), e);
        if (abs(dot(axes[a], c - d.center)) > d.halfSize[a] + boxReach) return false;
    }
    return true;
}

// Shadel shading's list (useShadelDecalList): its object's list (the culling pass's, the decals
// meeting the object's world bounds) with, per stage, a mask of the first 32 entries whose box
// holds the shadel's point; entries past 32 are all kept (a superset: each decal still
// tests its own box at every point, so a longer list only costs time).
bool gDecalShadelList = false;
uint gDecalStageMask[DECAL_STAGES];

void useDecalRanges(DecalFrame df, uint64_t ranges, uint index) {
    gDecals = df.decals;
    gDecalEntries = df.entries;
    for (uint st = 0u; st < DECAL_STAGES; ++st)
        gDecalRanges[st] = DecalRangeBuffer(ranges).r[index * DECAL_STAGES + st];
}

// Forward shading (and the shadel path's forward fallbacks): the lists of this pixel's tile.
void useTileDecalList(FrameConstants f, vec2 fragCoord) {
    if (f.decals == 0ul) return;
    DecalFrame df = DecalFrameRef(f.decals).d;
    uvec2 tile = uvec2(fragCoord) / LIGHT_TILE_SIZE;
    uint index = min(tile.y, df.tilesY - 1u) * df.tilesX + min(tile.x, df.tilesX - 1u);
    useDecalRanges(df, df.tileRanges, index);
}

// The decal's box holds world point p (the test applyDecal makes).
bool decalHolds(GpuDecal d, vec3 p) {
    return all(lessThanEqual(abs((d.worldToBox * vec4(p, 1.0)).xyz), vec3(0.5)));
}

// Shadel shading: the decals of object `object`'s list whose box holds the shadel's point p (its
// material is evaluated there for every prefilter sample, shadel/prefilter.glsl, so this is the
// exact list). Per invocation, in registers: no chunk box, no barrier. Returns the (decal,
// shadel) pairs kept.
uint useShadelDecalList(FrameConstants f, uint object, vec3 p) {
    gDecals = 0ul;
    if (f.decals == 0ul) return 0u;
    DecalFrame df = DecalFrameRef(f.decals).d;
    if (object >= df.instanceCount) return 0u;
    uvec2 range = DecalRangeBuffer(df.objectRanges).r[object];
    if (range.y == 0u) return 0u;
    if (range.y == DECAL_OBJECT_ALL) { // the object's list did not fit: every frustum decal
        gDecalEntries = df.frustumDecals;
        range = uvec2(0u, df.frustumDecalCount);
    } else {
        gDecalEntries = df.entries;
    }
    DecalBuffer decals = DecalBuffer(df.decals);
    UintBuffer entries = UintBuffer(gDecalEntries);
    uint kinds = 0u, pairs = 0u;
    for (uint st = 0u; st < DECAL_STAGES; ++st) gDecalStageMask[st] = 0u;
    for (uint i = 0u; i < range.y; ++i) {
        GpuDecal d = decals.d[entries.v[range.x + i]];
        if (i < 32u && !decalHolds(d, p)) continue;
        for (uint st = 0u; st < DECAL_STAGES; ++st)
            if (i < 32u && (d.kinds & DECAL_KIND(st)) != 0u) gDecalStageMask[st] |= 1u << i;
        kinds |= d.kinds;
        pairs++;
    }
    if (kinds == 0u) return 0u;
    gDecals = df.decals;
    gDecalShadelList = true;
    for (uint st = 0u; st < DECAL_STAGES; ++st)
        gDecalRanges[st] = uvec2(range.x, (kinds & DECAL_KIND(st)) != 0u ? range.y : 0u);
    return pairs;
}

// The decal's coverage at box point b (|b| <= 0.5 on every axis), and for bump patterns the
// gradient of its height (per unit of the decal's u, v).
float decalPattern(GpuDecal d, vec3 b, out vec2 heightGradient) {
    vec2 uv = b.xy + 0.5;
    vec2 c = uv - 0.5;
    float r = length(c) * 2.0;
    heightGradient = vec2(0.0);
    // Every pattern fades out towards the box's sides (no hard cut where the box ends).
    float edge = 1.0 - smoothstep(0.4, 0.5, max(abs(b.x), abs(b.y)));
    if (d.pattern == DECAL_PATTERN_SPLAT) {
        float disc = 1.0 - smoothstep(0.3, 0.42, r);
        float ring = smoothstep(0.55, 0.65, r) * (1.0 - smoothstep(0.78, 0.88, r));
        return max(disc, ring);
    }
    if (d.pattern == DECAL_PATTERN_STRIPES) {
        float t = fract((uv.x + uv.y) * 2.0);
        return smoothstep(0.1, 0.25, t) * (1.0 - smoothstep(0.5, 0.65, t)) * edge;
    }
    if (d.pattern == DECAL_PATTERN_RIVETS) {
        const float cells = 4.0, radius = 0.32;
        vec2 cell = fract(uv * cells) - 0.5;
        float rr = length(cell) / radius;
        if (rr >= 1.0) return 0.0;
        // height = (cos(pi rr) + 1) / 2: smooth dome, flat at its rim
        float dh = -0.5 * 3.14159265 * sin(3.14159265 * rr);
        heightGradient = dh * (cell / max(length(cell), 1e-5)) / radius * cells * edge;
        return (cos(3.14159265 * rr) * 0.5 + 0.5) * edge;
    }
    if (d.pattern == DECAL_PATTERN_PUDDLE) {
        float a = atan(c.y, c.x);
        float wobble = 1.0 + 0.12 * sin(3.0 * a + 0.5) + 0.08 * sin(5.0 * a + 2.0);
        return 1.0 - smoothstep(0.55, 0.85, r * wobble);
    }
    // DECAL_PATTERN_BLOB: a contact shadow, darkest in the middle.
    return 1.0 - smoothstep(0.1, 1.0, r);
}

// Stage `st` of decal d at world point p, geometric normal n (which faces the box's projection
// decides how much of a decal a surface takes).
void applyDecal(uint st, GpuDecal d, inout MaterialSample o, vec3 p, vec3 n) {
    vec3 b = (d.worldToBox * vec4(p, 1.0)).xyz;
    if (any(greaterThan(abs(b), vec3(0.5)))) return;
    // Fade near the box's front and back faces and on surfaces turned away from its axis.
    float fade = (1.0 - smoothstep(0.35, 0.5, abs(b.z))) *
                 smoothstep(0.2, 0.5, dot(n, d.axisZ));
    if (fade <= 0.0) return;
    vec2 gradient;
    float mask = decalPattern(d, b, gradient) * fade;
    if (st == DECAL_STAGE_BASE_COLOR) {
        o.baseColor = mix(o.baseColor, d.color.rgb, d.color.a * mask);
    } else if (st == DECAL_STAGE_NORMAL) {
        // Height gradient per metre along the box's faces, kept in the surface's plane.
        vec3 g = gradient.x * d.axisX / (2.0 * d.halfSize.x) +
                 gradient.y * d.axisY / (2.0 * d.halfSize.y);
        g -= o.normal * dot(o.normal, g);
        o.normal = normalize(o.normal - g * (0.02 * d.normalStrength * fade));
    } else if (st == DECAL_STAGE_ROUGHNESS) {
        o.roughness = clamp(mix(o.roughness, d.roughness, mask), 0.0, 1.0);
    } else {
        o.ambientOcclusion *= 1.0 - d.occlusion * mask;
    }
}

// Stage `st` of every decal in the chosen list, in decal order.
void applyDecalStage(uint st, inout MaterialSample o, vec3 p, vec3 n) {
    DecalBuffer decals = DecalBuffer(gDecals);
    UintBuffer entries = UintBuffer(gDecalEntries);
    uvec2 range = gDecalRanges[st];
    if (gDecalShadelList) { // the stage's mask over the first 32, then the stage's later ones
        for (uint m = gDecalStageMask[st]; m != 0u; m &= m - 1u)
            applyDecal(st, decals.d[entries.v[range.x + uint(findLSB(m))]], o, p, n);
        for (uint i = 32u; i < range.y; ++i) {
            uint index = entries.v[range.x + i];
            if ((decals.d[index].kinds & DECAL_KIND(st)) != 0u) applyDecal(st, decals.d[index], o, p, n);
        }
        return;
    }
    for (uint i = 0u; i < range.y; ++i) applyDecal(st, decals.d[entries.v[range.x + i]], o, p, n);
}

// Every stage, in order, when the caller chose a list (see the top of this file).
void applyDecals(inout MaterialSample o, vec3 p, vec3 n) {
    if (gDecals == 0ul) return;
    for (uint st = 0u; st < DECAL_STAGES; ++st)
        if (gDecalRanges[st].y != 0u) applyDecalStage(st, o, p, n);
}
#endif
