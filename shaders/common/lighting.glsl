// Lighting shared by the forward and decoupled paths: GGX specular + Lambert diffuse, the
// sun with a PCF shadow map, and one buffer of lights of several kinds: omni, spot
// with a round or square cone (optionally projecting a texture: gobos), tube
// (representative-point specular), textured rectangular area lights, darks (negative lights),
// each optionally limited by a clip plane and stopped by light blockers with portals.
//
// Which lights a surface loops over is chosen by the caller before shadeSurface (render/lighting):
// every light (LIGHT_LIST_ALL), a screen tile's list in memory (forward, useTileLightList), the
// light grid's candidates at one point (forward pixels of a frame without screen tiles:
// decoupled frames, whose shadel chunks cull against the grid themselves), the workgroup's
// list in shared memory (shadel chunks; the shader defines SHADEL_LIGHT_LIST_SHARED) or, with
// few lights, a bit set the subgroup culled for itself (LIGHT_LIST_SUBGROUP, forward pixels and
// shadel chunks alike: lighting/light_cull.glsl useSubgroupLightList).
// A list entry is (light, mask): bit k of the mask asks for the per-pixel test of the light's
// k-th blocker; culling has already removed lights a blocker hides from the whole tile.
#ifndef SHADEL_LIGHTING_GLSL
#define SHADEL_LIGHTING_GLSL
#include "common/material.glsl"
#include "gi/lpv_sample.glsl"
#include "distance_fields/distance_fields.glsl"

layout(buffer_reference, scalar) readonly buffer LightingFrameRef { LightingFrame l; };
layout(buffer_reference, scalar) readonly buffer LightBlockerBuffer { GpuLightBlocker b[]; };
layout(buffer_reference, scalar) readonly buffer LightPortalBuffer { GpuLightPortal p[]; };
layout(buffer_reference, scalar) readonly buffer LightListBuffer { uvec2 e[]; };
layout(buffer_reference, scalar) buffer LightingCountersRef { LightingCounters c; };
layout(buffer_reference, scalar) readonly buffer SpotShadowBuffer { GpuSpotShadow s[]; };
layout(buffer_reference, scalar) readonly buffer LightGridRef { GpuLightGrid g; };
layout(buffer_reference, scalar) readonly buffer LightGridBuckets { uvec2 b[]; };
layout(buffer_reference, scalar) readonly buffer LightGridEntries { uint v[]; };

#define LIGHT_LIST_ALL 0u
#define LIGHT_LIST_BUFFER 1u
#define LIGHT_LIST_SHARED 2u
#define LIGHT_LIST_GRID 3u
#define LIGHT_LIST_SUBGROUP 4u
#define LIGHT_TILE_MAX_LIGHTS 1024u // lights a tile's list can hold (shared memory while culling)
#define LIGHT_CHUNK_MAX_LIGHTS 512u // entries of a shadel chunk's list (shared memory)
#define LIGHT_INVALID 0xFFFFFFFFu   // an entry culling removed in place

// Feature spectra (render/lighting/feature_spectra.h): the SPECTRUM_* features this
// pipeline compiles in. Every feature by default; a tile-shading permutation sets fewer, and
// the branches of the features it lacks are dead code the compiler removes (fewer registers).
// Only tiles that need none of the missing features are shaded by such a permutation, so the
// result is the same.
layout(constant_id = SPECTRUM_FEATURES_CONSTANT_ID) const uint kSpectrumFeatures = SPECTRUM_ALL;
#define SPECTRUM_HAS(features) ((kSpectrumFeatures & (features)) != 0u)
// Spectra per light: the first gLightListPlainCount entries of a tile's list read no texture
// (SPECTRUM_SAMPLING_LIGHTS), and a pipeline with kSpectrumLightSplit shades them in a loop
// compiled without those features: the raster forward pass and the spectra permutations that
// have them (forward tiles, whose list is in memory: on lavapipe the code of the features
// compiled in costs every light there whether it uses them or not; builtin:lights 1280x720,
// tile shading with every light that reads a texture skipped: 239 ms without their code, 305
// with it). Other lists (grid, subgroup, chunk) leave the count 0: one loop with every feature.
layout(constant_id = SPECTRUM_LIGHT_SPLIT_CONSTANT_ID) const uint kSpectrumLightSplit = 0u;
uint gLightListPlainCount = 0u;

// Distance-field far shadows and AO (render/distance_fields): compiled in only by the pipelines
// that set the constant (forward and shadel shading with --distance-fields on), so other scenes
// and passes do not carry the tracing code.
layout(constant_id = DISTANCE_FIELD_LIGHTING_CONSTANT_ID) const uint kDistanceFieldLighting = 0u;

uint gLightListMode = LIGHT_LIST_ALL;
uint64_t gLightListAddress = 0ul;
uint gLightListCount = 0u;
uvec2 gGridLists[3]; // LIGHT_LIST_GRID: global, big and bucket lists (first entry, count)
uint gGridBlockerMask = 0u;
// LIGHT_LIST_SUBGROUP (light_cull.glsl, useSubgroupLightList): the lights kept for the subgroup,
// a bit per light (uniform over the subgroup), and the blocker mask every kept light takes.
uvec2 gSubgroupLights = uvec2(0u);
uint gSubgroupBlockerMask = 0u;

#ifdef SHADEL_LIGHT_LIST_SHARED
shared uvec2 sLightList[LIGHT_CHUNK_MAX_LIGHTS];
shared uint sLightListCount;
#endif

// A tile's range (first entry, packTileListLength): its entries, and how many of the leading
// ones read no texture (the tile pass lists those first; gLightListPlainCount).
uint packTileListLength(uint count, uint plain) { return count | (plain << 16); }

// Forward shading: the list of the 16x16 tile holding this pixel, when tiled culling ran.
void useTileLightList(FrameConstants f, vec2 fragCoord) {
    if (f.lighting == 0ul) return;
    LightingFrame lf = LightingFrameRef(f.lighting).l;
    if (lf.tiled == 0u) return;
    uvec2 tile = uvec2(fragCoord) / LIGHT_TILE_SIZE;
    uint index = min(tile.y, lf.tilesY - 1u) * lf.tilesX + min(tile.x, lf.tilesX - 1u);
    uvec2 range = LightListBuffer(lf.tileRanges).e[index];
    gLightListMode = LIGHT_LIST_BUFFER;
    gLightListAddress = lf.tileLights + uint64_t(range.x) * 8ul;
    gLightListCount = range.y & 0xFFFFu;
    gLightListPlainCount = range.y >> 16;
}

// A forward pixel at `position`: its tile's list when screen tiles were culled this frame,
// else the light grid's candidates at the point (the global list, level 0's big list and the
// bucket of the point's cell: no light is listed twice there), each of whose blockers is
// tested per pixel. Lights beyond their range add nothing, so the sum is the all-lights sum.
void useLightListAt(FrameConstants f, vec2 fragCoord, vec3 position) {
    if (f.lighting == 0ul) return;
    LightingFrame lf = LightingFrameRef(f.lighting).l;
    if (lf.screenTiles != 0u) {
        useTileLightList(f, fragCoord);
        return;
    }
    if (lf.tiled == 0u || lf.lightGrid == 0ul) return;
    GpuLightGrid g = LightGridRef(lf.lightGrid).g;
    if (g.levels == 0u) return;
    vec3 c = floor((position - g.origin) / g.cellSize);
    if (any(greaterThanEqual(abs(c), vec3(LIGHT_GRID_MAX_CELL)))) return;
    ivec3 cell = ivec3(c);
    gLightListMode = LIGHT_LIST_GRID;
    gLightListAddress = g.entries;
    gGridLists[0] = uvec2(g.globalFirst, g.globalCount);
    gGridLists[1] = g.big[0];
    gGridLists[2] = LightGridBuckets(g.buckets).b[LIGHT_GRID_HASH(cell.x, cell.y, cell.z)];
    gLightListCount = gGridLists[0].y + gGridLists[1].y + gGridLists[2].y;
    gGridBlockerMask = lf.blockersOn != 0u ? 0xFFFFFFFFu : 0u;
}

uint lightListLength(FrameConstants f) {
    if (gLightListMode == LIGHT_LIST_BUFFER || gLightListMode == LIGHT_LIST_GRID)
        return gLightListCount;
#ifdef SHADEL_LIGHT_LIST_SHARED
    if (gLightListMode == LIGHT_LIST_SHARED) return min(sLightListCount, LIGHT_CHUNK_MAX_LIGHTS);
#endif
    if (gLightListMode == LIGHT_LIST_SUBGROUP)
        return uint(bitCount(gSubgroupLights.x) + bitCount(gSubgroupLights.y));
    return f.lightCount;
}

uvec2 lightListEntry(FrameConstants f, uint i) {
    if (gLightListMode == LIGHT_LIST_BUFFER) return LightListBuffer(gLightListAddress).e[i];
    if (gLightListMode == LIGHT_LIST_GRID) {
        uint list = i < gGridLists[0].y ? 0u : i < gGridLists[0].y + gGridLists[1].y ? 1u : 2u;
        uint skip = list == 0u   ? 0u
                    : list == 1u ? gGridLists[0].y
                                 : gGridLists[0].y + gGridLists[1].y;
        uint light = LightGridEntries(gLightListAddress).v[gGridLists[list].x + i - skip];
        return uvec2(light, gGridBlockerMask);
    }
#ifdef SHADEL_LIGHT_LIST_SHARED
    if (gLightListMode == LIGHT_LIST_SHARED) return sLightList[i];
#endif
    if (gLightListMode == LIGHT_LIST_SUBGROUP) { // the i-th set bit
        uint low = uint(bitCount(gSubgroupLights.x));
        uint word = i < low ? gSubgroupLights.x : gSubgroupLights.y;
        for (uint k = i < low ? i : i - low; k > 0u; --k) word &= word - 1u;
        return uvec2(uint(findLSB(word)) + (i < low ? 0u : 32u), gSubgroupBlockerMask);
    }
    // Every light: no culling happened, so every blocker a light lists is tested per pixel.
    bool blockers = f.lighting != 0ul && LightingFrameRef(f.lighting).l.blockersOn != 0u;
    return uvec2(i, blockers ? 0xFFFFFFFFu : 0u);
}

const float PI = 3.14159265358979;

// GGX alpha of a light's specular lobe: a punctual light on a perfect mirror is a delta the
// lobe cannot hold, so the lights floor perceptual roughness at 0.04. Materials keep the
// authored value: the environment's mirror level (roughness 0) is read as authored.
float lightLobeAlpha(float perceptualRoughness) {
    float r = max(perceptualRoughness, 0.04);
    return r * r;
}

float distributionGgx(float nh, float a2) {
    float d = nh * nh * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

float visibilitySmithGgx(float nv, float nl, float a2) {
    float gv = nl * sqrt(nv * nv * (1.0 - a2) + a2);
    float gl = nv * sqrt(nl * nl * (1.0 - a2) + a2);
    return 0.5 / max(gv + gl, 1e-5);
}

// KHR_materials_sheen: Charlie distribution and Neubelt's visibility (Estevez and Kulla 2017).
float distributionCharlie(float nh, float alpha) {
    float inv = 1.0 / alpha;
    float sin2 = max(1.0 - nh * nh, 0.0078125);
    return (2.0 + inv) * pow(sin2, inv * 0.5) / (2.0 * PI);
}

// The glTF metal/rough BRDF is a mix, by metallic, of two BRDFs with their own Fresnel terms: a
// dielectric (Lambert diffuse under a specular layer whose F0/F90 come from ior and
// KHR_materials_specular; what the layer reflects does not reach the diffuse) and a metal
// (specular only, F0 = base colour). Both share the GGX microfacet term D * V.
vec3 dielectricFresnel(MaterialSample m, float vh) {
    return m.specularF0 + (m.specularF90 - m.specularF0) * pow(1.0 - vh, 5.0);
}
// The weights of the diffuse (Lambert, albedo baseColor / pi) and of the specular D * V terms.
void gltfFresnelWeights(MaterialSample m, float vh, out vec3 diffuseWeight, out vec3 specularWeight) {
    vec3 dielectric = dielectricFresnel(m, vh);
    vec3 metal = m.baseColor + (1.0 - m.baseColor) * pow(1.0 - vh, 5.0);
    diffuseWeight = (1.0 - m.metallic) * (1.0 - dielectric);
    specularWeight = mix(dielectric, metal, m.metallic);
}

#include "common/transmission.glsl"

// The clear coat's Fresnel toward the viewer, times its weight: what the coat reflects of the
// light and the environment and takes from the layers below (KHR_materials_clearcoat).
float clearcoatFresnel(MaterialSample m, vec3 v) {
    float cnv = max(dot(m.clearcoatNormal, v), 0.0);
    return m.clearcoat * (0.04 + 0.96 * pow(1.0 - cnv, 5.0));
}

// Radiance reflected toward v from a light of `radiance` arriving from direction l: the base
// layer (the glTF BRDF above), under sheen (the layer below scaled by m.sheenAlbedoScale), under
// the clear coat (Fresnel on its own normal; what it reflects does not reach the
// layers below).
vec3 brdf(MaterialSample m, vec3 n, vec3 v, vec3 l, vec3 radiance) {
    float nl = dot(n, l);
    bool coat = MATERIAL_HAS(MATERIAL_FEATURE_CLEARCOAT) && m.clearcoat > 0.0;
    float coatNl = coat ? dot(m.clearcoatNormal, l) : 0.0;
    bool transmits = transmissionLobe(); // (false, compiled out, outside the transmission pass)
    if (nl <= 0.0 && coatNl <= 0.0 && !transmits) return vec3(0.0);
    vec3 h = normalize(v + l);
    float vh = max(dot(v, h), 0.0);
    vec3 color = vec3(0.0);
    if (nl > 0.0) {
        float nv = max(dot(n, v), 1e-4);
        float nh = max(dot(n, h), 0.0);
        float a = lightLobeAlpha(m.roughness);
        float a2 = a * a;
        vec3 diffuseWeight, specularWeight;
        gltfFresnelWeights(m, vh, diffuseWeight, specularWeight);
        float specular = distributionGgx(nh, a2) * visibilitySmithGgx(nv, nl, a2);
        color = diffuseWeight * m.baseColor / PI + specularWeight * specular;
        float sheenMax = max(m.sheenColor.r, max(m.sheenColor.g, m.sheenColor.b));
        if (MATERIAL_HAS(MATERIAL_FEATURE_SHEEN) && sheenMax > 0.0) {
            float alpha = m.sheenRoughness * m.sheenRoughness;
            vec3 sheen = m.sheenColor * distributionCharlie(nh, alpha) /
                         (4.0 * (nl + nv - nl * nv));
            color = color * m.sheenAlbedoScale + sheen;
        }
        color *= nl;
    }
    if (transmits) {
        // transmissionFactor of the diffuse lobe's share transmits the light from behind
        // instead (KHR_materials_transmission), under the same Fresnel weight: at the half
        // vector of the light mirrored through the surface when it lies behind (v + l may
        // vanish there).
        float vhT = nl > 0.0 ? vh : max(dot(v, normalize(reflect(l, n) + v)), 0.0);
        vec3 diffuseWeight, specularWeight;
        gltfFresnelWeights(m, vhT, diffuseWeight, specularWeight);
        vec3 lambert = m.baseColor / PI * max(nl, 0.0);
        color += diffuseWeight * gTransmission.factor * (transmissionBtdf(m, n, v, l) - lambert);
    }
    if (coat) {
        vec3 cn = m.clearcoatNormal;
        float fc = clearcoatFresnel(m, v);
        vec3 coatColor = vec3(0.0);
        if (coatNl > 0.0) {
            float ca = lightLobeAlpha(m.clearcoatRoughness);
            float ca2 = ca * ca;
            coatColor = vec3(distributionGgx(max(dot(cn, h), 0.0), ca2) *
                             visibilitySmithGgx(max(dot(cn, v), 1e-4), coatNl, ca2) * coatNl);
        }
        color = mix(color, coatColor, fc);
    }
    return color * radiance;
}

#include "common/environment_lighting.glsl"
#include "lighting/shadows.glsl"

// 3x3 PCF on the sun's shadow map (reversed-Z is not used for the orthographic shadow map):
// the cascade holding the point (--sun-cascades 2..4), else the one map fitted to the scene.
float sunShadow(FrameConstants f, vec3 worldPos, vec3 n) {
    if (f.sunShadowSlot == NO_TEXTURE) return 1.0;
    float cascaded;
    if (sunCascadeShadow(f, worldPos, n, false, cascaded)) return cascaded;
    // Normal offset scaled by the texel size keeps acne away on grazing surfaces.
    vec3 p = worldPos + n * f.shadowTexelSize * 1.5;
    vec4 clip = f.sunViewProj * vec4(p, 1.0);
    vec3 ndc = clip.xyz / clip.w;
    vec2 uv = ndc.xy * 0.5 + 0.5;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || ndc.z > 1.0) return 1.0;
    float depth = ndc.z - 0.0015;
    vec2 texel = 1.0 / vec2(textureSize(gTextures[f.sunShadowSlot], 0));
    float lit = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x)
            lit += texture(sampler2DShadow(gTextures[f.sunShadowSlot], gShadowSamplers[SAMPLER_SHADOW]),
                           vec3(uv + vec2(x, y) * texel, depth));
    return lit / 9.0;
}

// The smooth cut-off of a light's range alone (1 for an infinite range).
float rangeWindow(float distance, float range) {
    if (range <= 0.0) return 1.0;
    float r = distance / range;
    float window = clamp(1.0 - r * r * r * r, 0.0, 1.0);
    return window * window;
}

float rangeAttenuation(float distance, float range) {
    float invSquare = 1.0 / max(distance * distance, 1e-4);
    if (range <= 0.0) return invSquare;
    float r = distance / range;
    float window = clamp(1.0 - r * r * r * r, 0.0, 1.0);
    return invSquare * window * window;
}

// Whether blocker b stops light travelling from `lightPos` to p: the segment crosses the
// blocker's rectangle outside every portal.
bool blockerStops(GpuLightBlocker b, LightPortalBuffer portals, vec3 p, vec3 lightPos) {
    float dp = dot(b.normal, p - b.center);
    float dl = dot(b.normal, lightPos - b.center);
    if (dp * dl >= 0.0) return false; // same side (or on the plane)
    vec3 hit = p + (lightPos - p) * (dp / (dp - dl)) - b.center;
    vec2 uv = vec2(dot(hit, b.axisU), dot(hit, b.axisV));
    if (abs(uv.x) > b.halfU || abs(uv.y) > b.halfV) return false;
    if (!SPECTRUM_HAS(SPECTRUM_PORTALS)) return true;
    for (uint k = 0u; k < b.portalCount; ++k) {
        GpuLightPortal portal = portals.p[b.firstPortal + k];
        if (all(greaterThanEqual(uv, portal.minUv)) && all(lessThanEqual(uv, portal.maxUv)))
            return false;
    }
    return true;
}

// The per-pixel blocker test of the blockers `mask` selects among the light's list.
bool lightBlockedAt(FrameConstants f, GpuLight light, uint mask, vec3 p) {
    if (mask == 0u || light.blockerCount == 0u || f.lighting == 0ul) return false;
    LightingFrame lf = LightingFrameRef(f.lighting).l;
    if (lf.blockersOn == 0u) return false;
    LightBlockerBuffer blockers = LightBlockerBuffer(lf.blockers);
    LightPortalBuffer portals = LightPortalBuffer(lf.portals);
    UintBuffer list = UintBuffer(lf.lightBlockers);
    uint n = min(light.blockerCount, LIGHT_MAX_BLOCKERS_PER_LIGHT);
    for (uint k = 0u; k < n; ++k) {
        if ((mask & (1u << k)) == 0u) continue;
        if (blockerStops(blockers.b[list.v[light.blockerFirst + k]], portals, p, light.position))
            return true;
    }
    return false;
}

// Cone factor of round and square spots (1 inside the inner cone, 0 outside the outer).
float spotFactor(GpuLight light, vec3 dirToLight) {
    if (SPECTRUM_HAS(SPECTRUM_SPOT) && light.type == LIGHT_SPOT) {
        float cd = dot(light.direction, -dirToLight);
        float s = clamp(cd * light.spotScale + light.spotOffset, 0.0, 1.0);
        return s * s;
    }
    if (SPECTRUM_HAS(SPECTRUM_SQUARE_SPOT) && light.type == LIGHT_SPOT_SQUARE) {
        float z = dot(light.direction, -dirToLight);
        if (z <= 0.0) return 0.0;
        vec3 up = cross(light.direction, light.axis);
        float t = max(abs(dot(light.axis, -dirToLight)), abs(dot(up, -dirToLight))) / z;
        float s = clamp(light.spotOffset - t * light.spotScale, 0.0, 1.0);
        return s * s;
    }
    return 1.0;
}

// Specular of a tube light from its representative point: the point of the segment closest to
// the reflection ray (Karis 2013), with the lobe widened by the tube's radius to keep energy.
vec3 tubeLight(GpuLight light, MaterialSample m, vec3 n, vec3 v, vec3 p) {
    vec3 a = light.position - light.axis * light.halfLength - p;
    vec3 b = light.position + light.axis * light.halfLength - p;
    vec3 ab = b - a;
    // Diffuse: the segment's point closest to the surface point.
    float td = clamp(-dot(a, ab) / max(dot(ab, ab), 1e-8), 0.0, 1.0);
    vec3 ld = a + ab * td;
    float distD = length(ld);
    vec3 dirD = ld / max(distD, 1e-4);
    // Specular: the point closest to the reflection ray.
    vec3 r = reflect(-v, n);
    float rab = dot(r, ab);
    float ts = (dot(r, a) * rab - dot(a, ab)) / max(dot(ab, ab) - rab * rab, 1e-8);
    ts = clamp(ts, 0.0, 1.0);
    vec3 ls = a + ab * ts;
    float distS = length(ls);
    vec3 dirS = ls / max(distS, 1e-4);

    float nlD = dot(n, dirD);
    float nlS = dot(n, dirS);
    float alpha = lightLobeAlpha(m.roughness);
    vec3 color = vec3(0.0);
    vec3 diffuseWeight, specularWeight;
    if (nlD > 0.0) {
        vec3 radiance = light.color * rangeAttenuation(distD, light.range);
        gltfFresnelWeights(m, max(dot(v, normalize(v + dirD)), 0.0), diffuseWeight, specularWeight);
        color += diffuseWeight * m.baseColor / PI * radiance * nlD;
    }
    if (nlS > 0.0) {
        vec3 radiance = light.color * rangeAttenuation(distS, light.range);
        float widened = clamp(alpha + light.radius / (2.0 * max(distS, 1e-4)), 0.0, 1.0);
        float energy = (alpha * alpha) / max(widened * widened, 1e-6);
        vec3 h = normalize(v + dirS);
        float a2 = widened * widened;
        gltfFresnelWeights(m, max(dot(v, h), 0.0), diffuseWeight, specularWeight);
        vec3 spec = specularWeight * distributionGgx(max(dot(n, h), 0.0), a2) *
                    visibilitySmithGgx(max(dot(n, v), 1e-4), nlS, a2);
        color += spec * energy * radiance * nlS;
    }
    return color;
}

// Metres one pixel spans at the point being shaded (set by shadeSurface; 0: the finest MIP).
// Gobos pick the MIP of their texture from it, so pixels and shadels (which shade the points
// pixels will show) filter the projected pattern alike.
float gLightFootprint = 0.0;

// A gobo: what the spot's texture lets through toward p (dirToLight from p, dist to the light).
// UV from the tangent of the angle off the axis along the spot's right (axis) and up
// (cross(axis, direction)) vectors, texture rows top first; the MIP from a texel's width at p
// against the pixel's.
vec3 goboColor(GpuLight light, vec3 dirToLight, float dist) {
    vec3 d = -dirToLight;
    float z = dot(light.direction, d);
    if (z <= 1e-4) return vec3(0.0);
    vec3 up = cross(light.axis, light.direction); // upright seen from behind the light
    vec2 t = vec2(dot(light.axis, d), dot(up, d)) / z;
    vec2 uv = vec2(0.5 + t.x * light.textureScale, 0.5 - t.y * light.textureScale);
    float texels = float(textureSize(gTextures[nonuniformEXT(light.textureSlot)], 0).x);
    float texelMetres = dist / (z * light.textureScale * texels);
    float lod = log2(max(gLightFootprint / max(texelMetres, 1e-6), 1.0));
    return sampleTextureLod(light.textureSlot, SAMPLER_LINEAR_REPEAT, uv, lod).rgb;
}

// An area light's emitted colour (times light.color) at rectangle coordinates s in [-1, 1]^2
// (right, up), filtered to MIP `lod`; a flat emitter without a texture.
vec3 areaTexel(GpuLight light, vec2 s, float lod) {
    if (light.textureSlot == NO_TEXTURE) return vec3(1.0);
    vec2 uv = vec2(0.5 + 0.5 * s.x, 0.5 - 0.5 * s.y);
    return sampleTextureLod(light.textureSlot, SAMPLER_LINEAR_CLAMP, uv, lod).rgb;
}

// Texels across the wider side of an area light's texture (1 without one).
float areaTexels(GpuLight light) {
    if (light.textureSlot == NO_TEXTURE) return 1.0;
    ivec2 size = textureSize(gTextures[nonuniformEXT(light.textureSlot)], 0);
    return float(max(size.x, size.y));
}

#define AREA_DIFFUSE_CELLS 4        // per side: the diffuse integral's samples
#define AREA_FAR_HALF_DIAGONALS 6.0 // beyond this distance: one sample (<= 2% off the 4x4)

// A textured, one-sided rectangular area light (an approximation, not the exact integral):
// diffuse from AREA_DIFFUSE_CELLS^2 cells of the rectangle (one far away), each a small emitter
// of its own area at its centre with the texture averaged over it (the MIP whose texel is the
// cell), so a distant surface sees the texture's mean colour and a near one its layout; specular
// from one
// representative point (the rectangle's point closest to where the reflection ray meets its
// plane), treated as a point light of the rectangle's power there with Karis's normalization for
// the lobe the rectangle widens, the texture read at a MIP as wide as the lobe's footprint.
vec3 areaLight(GpuLight light, MaterialSample m, vec3 n, vec3 v, vec3 p) {
    vec3 emitNormal = light.direction;
    vec3 right = light.axis, up = cross(light.direction, light.axis);
    float hw = light.halfLength, hh = light.radius;
    if (dot(p - light.position, emitNormal) <= 0.0) return vec3(0.0); // behind the emitter
    float texels = areaTexels(light);
    float nv = max(dot(n, v), 1e-4);
    vec3 diffuseWeight, specularWeight;

    // Diffuse: irradiance summed over the cells. Farther than AREA_FAR_HALF_DIAGONALS half
    // diagonals the cells' terms differ little and one cell, the whole rectangle in its mean
    // colour, stands for them (the street's signs are mostly seen from there).
    vec3 fromCentre = p - light.position;
    bool far = dot(fromCentre, fromCentre) >
               AREA_FAR_HALF_DIAGONALS * AREA_FAR_HALF_DIAGONALS * (hw * hw + hh * hh);
    int side = far ? 1 : AREA_DIFFUSE_CELLS;
    float cells = float(side);
    float cellArea = 4.0 * hw * hh / (cells * cells);
    float cellLod = log2(max(texels / cells, 1.0));
    vec3 irradiance = vec3(0.0);
    vec3 meanDir = vec3(0.0);
    for (int j = 0; j < side; ++j)
        for (int i = 0; i < side; ++i) {
            vec2 s = (vec2(i, j) + 0.5) / cells * 2.0 - 1.0;
            vec3 toCell = light.position + right * (s.x * hw) + up * (s.y * hh) - p;
            float d2 = dot(toCell, toCell);
            float d = sqrt(d2);
            vec3 l = toCell / max(d, 1e-5);
            float cosReceiver = dot(n, l), cosEmitter = -dot(emitNormal, l);
            if (cosReceiver <= 0.0 || cosEmitter <= 0.0) continue;
            // A cell closer than its own size adds at most its radiance (no 1/d^2 blow-up).
            float w = cosReceiver * cosEmitter * cellArea / max(d2, cellArea) *
                      rangeWindow(d, light.range);
            irradiance += areaTexel(light, s, cellLod) * w;
            meanDir += l * w;
        }
    vec3 color = vec3(0.0);
    if (dot(meanDir, meanDir) > 0.0) {
        vec3 l = normalize(meanDir);
        gltfFresnelWeights(m, max(dot(v, normalize(v + l)), 0.0), diffuseWeight, specularWeight);
        color += diffuseWeight * m.baseColor / PI * irradiance * light.color;
    }

    // Specular: the representative point.
    vec3 r = reflect(-v, n);
    float front = dot(p - light.position, emitNormal);
    float rn = dot(r, emitNormal);
    vec3 hit = rn < -1e-4 ? p + r * (front / -rn) : p + r * length(light.position - p);
    vec3 local = hit - light.position;
    vec2 st = clamp(vec2(dot(local, right) / hw, dot(local, up) / hh), -1.0, 1.0);
    vec3 ls = light.position + right * (st.x * hw) + up * (st.y * hh) - p;
    float distS = length(ls);
    vec3 dirS = ls / max(distS, 1e-4);
    float nlS = dot(n, dirS), cosEmitter = -dot(emitNormal, dirS);
    if (nlS > 0.0 && cosEmitter > 0.0) {
        float alpha = lightLobeAlpha(m.roughness);
        float sourceRadius = sqrt(4.0 * hw * hh / PI); // a disc of the rectangle's area
        float widened = clamp(alpha + sourceRadius / (2.0 * max(distS, 1e-4)), 0.0, 1.0);
        float energy = (alpha * alpha) / max(widened * widened, 1e-6);
        float a2 = alpha * alpha;
        vec3 h = normalize(v + dirS);
        gltfFresnelWeights(m, max(dot(v, h), 0.0), diffuseWeight, specularWeight);
        vec3 spec = specularWeight * distributionGgx(max(dot(n, h), 0.0), a2) * visibilitySmithGgx(nv, nlS, a2);
        // The lobe's footprint on the rectangle, in texels: its MIP.
        float footprint = 2.0 * distS * widened;
        float lod = log2(max(footprint * texels / (2.0 * max(hw, hh)), 1.0));
        vec3 intensity = light.color * areaTexel(light, st, lod) * (4.0 * hw * hh) * cosEmitter;
        color += spec * energy * intensity * rangeAttenuation(distS, light.range) * nlS;
    }
    return color;
}

// One light of the buffer at surface point p (not counting blockers), with the SPECTRUM_*
// `features` compiled in (a constant after inlining).
vec3 evaluateLightWith(GpuLight light, MaterialSample m, vec3 n, vec3 v, vec3 p, uint features) {
    if (SPECTRUM_HAS(SPECTRUM_CLIP_PLANES) && (light.flags & LIGHT_FLAG_CLIP_PLANE) != 0u &&
        dot(light.clipPlane.xyz, p) + light.clipPlane.w < 0.0)
        return vec3(0.0);
    if (light.type == LIGHT_DIRECTIONAL) return brdf(m, n, v, -light.direction, light.color);
    if (light.type == LIGHT_TUBE)
        return SPECTRUM_HAS(SPECTRUM_TUBE) ? tubeLight(light, m, n, v, p) : vec3(0.0);
    if (light.type == LIGHT_AREA)
        return (features & SPECTRUM_AREA) != 0u ? areaLight(light, m, n, v, p) : vec3(0.0);
    if (!SPECTRUM_HAS(SPECTRUM_OMNI | SPECTRUM_SPOT | SPECTRUM_SQUARE_SPOT)) return vec3(0.0);
    vec3 toLight = light.position - p;
    float dist = length(toLight);
    vec3 dir = toLight / max(dist, 1e-4);
    vec3 radiance = light.color * rangeAttenuation(dist, light.range) * spotFactor(light, dir);
    // Beyond its range or outside its cone a light adds nothing: skip the BRDF (without light
    // culling, e.g. few lights on screen, every surface loops over every light).
    if (all(equal(radiance, vec3(0.0)))) return vec3(0.0);
    if ((features & SPECTRUM_PROJECTED) != 0u && (light.flags & LIGHT_FLAG_PROJECTED) != 0u &&
        any(notEqual(radiance, vec3(0.0))))
        radiance *= goboColor(light, dir, dist);
    return brdf(m, n, v, dir, radiance);
}

vec3 evaluateLight(GpuLight light, MaterialSample m, vec3 n, vec3 v, vec3 p) {
    return evaluateLightWith(light, m, n, v, p, kSpectrumFeatures);
}

// Ray-traced terms (render/raytracing, shaders/raytracing): the caller sets them before
// shadeSurface when the frame traces rays (forward: the pixel's, raytracing/rt_apply.glsl; the
// shadel path: the shadel's accumulated ones). Left unset: the shadow map and the plain ambient.
bool gRtSun = false;          // gRtSunVisibility replaces the sun's shadow map
float gRtSunVisibility = 1.0;
float gRtOcclusion = 1.0;     // ambient occlusion: multiplies the ambient term
vec3 gRtIndirect = vec3(0.0); // one-bounce diffuse light: irradiance / pi (times the albedo here)
// Ray-traced spot shadows: the visibility of each shadow-casting spot, 8 bits per
// GpuLight::shadowIndex (raytracing/rt_types.h), in place of the spot shadow maps.
bool gRtSpots = false;
uvec4 gRtSpotVisibility = uvec4(0xFFFFFFFFu);
// Out: the sun visibility the last shadeSurface lit with (shadow map, soft shadows, distance
// fields or ray traced). A caller lighting the same point again (shadels/prefilter.glsl: the
// same shadel with another base colour) passes it back as gRtSunVisibility instead of paying
// for the shadow taps twice.
float gSunVisibilityUsed = 1.0;

float rtSpotVisibility(uvec4 packed, uint shadowIndex) {
    return float((packed[shadowIndex >> 2u] >> ((shadowIndex & 3u) * 8u)) & 0xFFu) / 255.0;
}

// Entry i of the light list at worldPos, with the SPECTRUM_* `features` compiled in (a constant
// after inlining): its blockers per pixel, the light, its spot shadow.
vec3 listedLight(FrameConstants f, LightingFrame lf, bool haveLighting, uint i, MaterialSample m,
                 vec3 n, vec3 v, vec3 worldPos, vec3 geometricNormal, uint features) {
    uvec2 entry = lightListEntry(f, i);
    if (entry.x == LIGHT_INVALID) return vec3(0.0);
    GpuLight light = LightBuffer(f.lights).l[entry.x];
    if (SPECTRUM_HAS(SPECTRUM_BLOCKERS) && lightBlockedAt(f, light, entry.y, worldPos))
        return vec3(0.0);
    vec3 c = evaluateLightWith(light, m, n, v, worldPos, features);
    bool spotShadows = (features & SPECTRUM_SPOT_SHADOWS) != 0u && haveLighting &&
                       lf.spotShadowAtlas != NO_TEXTURE;
    if (spotShadows && light.shadowIndex != LIGHT_NO_SHADOW && any(notEqual(c, vec3(0.0))))
        c *= gRtSpots ? rtSpotVisibility(gRtSpotVisibility, light.shadowIndex)
                      : spotShadow(lf, light, worldPos, geometricNormal);
    return c;
}

// Everything that lights a surface point, evaluated for a viewer at f.cameraPosition.
vec3 shadeSurface(FrameConstants f, MaterialSample m, vec3 worldPos, vec3 geometricNormal) {
    if (m.unlit) return m.baseColor;
    vec3 n = m.normal;
    vec3 v = normalize(f.cameraPosition - worldPos);
    m = sheenForView(f.environment, m, n, v);
    // Emission leaves through the clear coat, which reflects its Fresnel's share back.
    bool coat = MATERIAL_HAS(MATERIAL_FEATURE_CLEARCOAT) && m.clearcoat > 0.0;
    vec3 color = m.emissive * (coat ? 1.0 - clearcoatFresnel(m, v) : 1.0);
    // Indirect diffuse light from the light propagation volume (0 when GI is off).
    vec3 indirect = giIrradiance(f.gi, worldPos, n) * m.baseColor * (1.0 - m.metallic) *
                    m.occlusion * m.ambientOcclusion / PI;
    if (f.visualize == VISUALIZE_GI) return indirect;
    if (f.visualize == VISUALIZE_RT_AO) return vec3(gRtOcclusion);
    color += indirect + gRtIndirect * m.baseColor * (1.0 - m.metallic) * m.occlusion *
                            m.ambientOcclusion;
    // Distance fields: AO on the environment; the sun's visibility in the far field.
    bool dfLighting = kDistanceFieldLighting != 0u && f.distanceFields != 0ul;
    DistanceFieldFrame df;
    float occlusion = m.occlusion * m.ambientOcclusion * gRtOcclusion; // AO decals: indirect only
    if (dfLighting) {
        df = DistanceFieldFrameRef(f.distanceFields).d;
        occlusion *= dfAmbientOcclusion(df, worldPos + geometricNormal * 0.02, geometricNormal);
    }
    // Image-based lighting (render/environment): the sky, an HDR file, or the scene's hemisphere.
    color += environmentLight(f.environment, m, n, v, occlusion);

    vec3 l = -f.sunDirection;
    LightingFrame lf;
    bool haveLighting = f.lighting != 0ul;
    if (haveLighting) lf = LightingFrameRef(f.lighting).l;
    if (dot(f.sunColor, f.sunColor) > 0.0) {
        float shadow = 1.0;
        if (gRtSun) // ray-traced sun visibility (render/raytracing), in place of the shadow map
            shadow = gRtSunVisibility;
        else if (SPECTRUM_HAS(SPECTRUM_SOFT_SHADOWS) && haveLighting && lf.sunSoftShadows != 0u)
            shadow = sunShadowSoft(f, lf, worldPos, geometricNormal);
        else if (SPECTRUM_HAS(SPECTRUM_SHADOWS))
            shadow = sunShadow(f, worldPos, geometricNormal);
        if (dfLighting && !gRtSun) {
            // Beyond the shadow map's range, with a band of a tenth of it where both blend.
            float dist = length(worldPos - f.cameraPosition);
            float far = f.dfShadowStart <= 0.0
                            ? 1.0
                            : clamp((dist - f.dfShadowStart) / (0.1 * f.dfShadowStart), 0.0, 1.0);
            if (far > 0.0) {
                float traced = dot(geometricNormal, l) > 0.0
                                   ? dfSoftShadow(df, worldPos + (geometricNormal + l) * 0.04, l, 400.0)
                                   : 0.0;
                shadow = mix(shadow, traced, far);
            }
        }
        color += brdf(m, n, v, l, f.sunColor * shadow);
        gSunVisibilityUsed = shadow;
    }
    // A pixel's width at this point (the gobos' MIP): view distance times the pixel's angle.
    gLightFootprint = length(worldPos - f.cameraPosition) * 2.0 / (f.proj[1][1] * f.viewportSize.y);

    vec3 direct = vec3(0.0);
    uint count = lightListLength(f);
    // Spectra per light: the leading lights that read no texture, in a loop without that code.
    uint plain = kSpectrumLightSplit != 0u ? min(gLightListPlainCount, count) : 0u;
    for (uint i = 0u; i < plain; ++i)
        direct += listedLight(f, lf, haveLighting, i, m, n, v, worldPos, geometricNormal,
                              kSpectrumFeatures & ~SPECTRUM_SAMPLING_LIGHTS);
    for (uint i = plain; i < count; ++i)
        direct += listedLight(f, lf, haveLighting, i, m, n, v, worldPos, geometricNormal,
                              kSpectrumFeatures);
    // Darks subtract light; they never make a surface emit negative light.
    // Without darks the sum is not negative and the clamp changes nothing.
    // The material's occlusion map darkens indirect light only (glTF), not the lights.
    if (!SPECTRUM_HAS(SPECTRUM_DARK)) return color + direct;
    return color + max(direct, -color);
}

// Wrap ("non-directional") diffuse of particles: n.l moved towards 1 by `wrap`, so
// thin media (smoke, mesh particles) are lit from behind too; wrap 0 is Lambert.
float wrappedNl(vec3 n, vec3 l, float wrap) {
    return max((dot(n, l) + wrap) / (1.0 + wrap), 0.0);
}

// The light reaching a diffuse particle of unit albedo at p with normal n, from the
// environment, the sun and every light of the caller's list (tube lights from their closest
// point). Linear in albedo, so the particle atlas stores this and sprites multiply their colour.
vec3 shadeParticle(FrameConstants f, vec3 p, vec3 n, float wrap) {
    vec3 color = environmentIrradiance(f.environment, n) + giIrradiance(f.gi, p, n) / PI;
    if (dot(f.sunColor, f.sunColor) > 0.0)
        color += f.sunColor * wrappedNl(n, -f.sunDirection, wrap) * sunShadow(f, p, n) / PI;
    LightBuffer lights = LightBuffer(f.lights);
    vec3 direct = vec3(0.0);
    uint count = lightListLength(f);
    for (uint i = 0u; i < count; ++i) {
        uvec2 entry = lightListEntry(f, i);
        if (entry.x == LIGHT_INVALID) continue;
        GpuLight light = lights.l[entry.x];
        if ((light.flags & LIGHT_FLAG_CLIP_PLANE) != 0u &&
            dot(light.clipPlane.xyz, p) + light.clipPlane.w < 0.0)
            continue;
        if (lightBlockedAt(f, light, entry.y, p)) continue;
        if (light.type == LIGHT_DIRECTIONAL) {
            direct += light.color * wrappedNl(n, -light.direction, wrap) / PI;
            continue;
        }
        vec3 at = light.position;
        vec3 power = light.color;
        if (light.type == LIGHT_TUBE) {
            float t = clamp(dot(p - light.position, light.axis), -light.halfLength, light.halfLength);
            at = light.position + light.axis * t;
        }
        if (light.type == LIGHT_AREA) {
            // The rectangle's closest point, as a point light of its power in its mean colour.
            vec3 up = cross(light.direction, light.axis);
            vec3 local = p - light.position;
            if (dot(local, light.direction) <= 0.0) continue; // behind the emitter
            at = light.position +
                 light.axis * clamp(dot(local, light.axis), -light.halfLength, light.halfLength) +
                 up * clamp(dot(local, up), -light.radius, light.radius);
            power *= areaTexel(light, vec2(0.0), log2(areaTexels(light))) *
                     (4.0 * light.halfLength * light.radius) *
                     max(dot(light.direction, normalize(p - at + light.direction * 1e-3)), 0.0);
        }
        vec3 toLight = at - p;
        float dist = length(toLight);
        vec3 dir = toLight / max(dist, 1e-4);
        vec3 radiance = power * rangeAttenuation(dist, light.range) * spotFactor(light, dir);
        if ((light.flags & LIGHT_FLAG_PROJECTED) != 0u) radiance *= goboColor(light, dir, dist);
        direct += radiance * wrappedNl(n, dir, wrap) / PI;
    }
    return color + max(direct, -color);
}
#endif
