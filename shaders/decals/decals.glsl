// Projected box decals (seeds 001 and 004, render/decals): applied to the material before
// lighting, in the material code both paths share (evaluateMaterial, common/material.glsl, calls
// applyDecals last). The caller picks the list first, as it does for lights: forward shading the
// list of its pixel's 16x16 tile (useTileDecalList), shadel shading the list of its chunk
// (useChunkDecalList), both built by the one culling pass (decals/decal_cull.comp). Without a
// list (every other caller of evaluateMaterial: transparency, ray hits, RSMs) nothing is applied.
//
// So in the shadel path a decal is evaluated once per shadel, at the shadel's surface point, and
// reused by every pixel (and frame) that reads the shadel, like the rest of the material.
//
// Stages run in order (base colour, normal, roughness, ambient occlusion; DECAL_STAGE_*), each
// over its own list in decal order, so overlapping decals combine the same way everywhere.
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

// Shadel shading: the lists of the chunk at `workIndex` of this frame's shading queue.
void useChunkDecalList(FrameConstants f, uint workIndex) {
    if (f.decals == 0ul) return;
    DecalFrame df = DecalFrameRef(f.decals).d;
    if (workIndex >= df.chunkCapacity) return;
    useDecalRanges(df, df.chunkRanges, workIndex);
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

// Stage `st` of every decal in the chosen list at world point p, geometric normal n (which
// faces the box's projection decides how much of a decal a surface takes).
void applyDecalStage(uint st, inout MaterialSample o, vec3 p, vec3 n) {
    DecalBuffer decals = DecalBuffer(gDecals);
    UintBuffer entries = UintBuffer(gDecalEntries);
    uvec2 range = gDecalRanges[st];
    for (uint i = 0u; i < range.y; ++i) {
        GpuDecal d = decals.d[entries.v[range.x + i]];
        vec3 b = (d.worldToBox * vec4(p, 1.0)).xyz;
        if (any(greaterThan(abs(b), vec3(0.5)))) continue;
        // Fade near the box's front and back faces and on surfaces turned away from its axis.
        float fade = (1.0 - smoothstep(0.35, 0.5, abs(b.z))) *
                     smoothstep(0.2, 0.5, dot(n, d.axisZ));
        if (fade <= 0.0) continue;
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
            o.roughness = clamp(mix(o.roughness, d.roughness, mask), 0.04, 1.0);
        } else {
            o.ambientOcclusion *= 1.0 - d.occlusion * mask;
        }
    }
}

// Every stage, in order, when the caller chose a list (see the top of this file).
void applyDecals(inout MaterialSample o, vec3 p, vec3 n) {
    if (gDecals == 0ul) return;
    for (uint st = 0u; st < DECAL_STAGES; ++st)
        if (gDecalRanges[st].y != 0u) applyDecalStage(st, o, p, n);
}
#endif
