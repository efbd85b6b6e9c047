// Shadow maps: the sun's (orthographic, its own map) and shadow-casting spots'
// (perspective, rectangles of one atlas, render/lighting/spot_shadows.h). PCF: a fixed 3x3
// kernel of hardware comparisons. PCSS (variable penumbra, Fernando 2005): a blocker search
// finds the mean depth of what occludes the point, the penumbra grows with the distance from
// that occluder to the receiver and with the emitter's size, and a PCF of that width filters.
#ifndef SHADEL_SHADOWS_GLSL
#define SHADEL_SHADOWS_GLSL

// Fixed Poisson disk (unit radius): no per-pixel rotation, so the filter is stable under a
// moving camera (banding at large penumbrae instead of noise).
const vec2 kShadowDisk[16] = vec2[16](
    vec2(-0.94201624, -0.39906216), vec2(0.94558609, -0.76890725), vec2(-0.09418410, -0.92938870),
    vec2(0.34495938, 0.29387760), vec2(-0.91588581, 0.45771432), vec2(-0.81544232, -0.87912464),
    vec2(-0.38277543, 0.27676845), vec2(0.97484398, 0.75648379), vec2(0.44323325, -0.97511554),
    vec2(0.53742981, -0.47373420), vec2(-0.26496911, -0.41893023), vec2(0.79197514, 0.19090188),
    vec2(-0.24188840, 0.99706507), vec2(-0.81409955, 0.91437590), vec2(0.19984126, 0.78641367),
    vec2(0.14383161, -0.14100790));

// A shadow map region: its UV rectangle (the whole map, or a spot's atlas rectangle) and texel.
struct ShadowRegion {
    uint slot;
    vec2 lo, hi; // UV clamp: taps stay inside the rectangle (half a texel in)
    vec2 texel;  // UV size of a texel
};

float shadowCompare(ShadowRegion r, vec2 uv, float depth) {
    return texture(sampler2DShadow(gTextures[r.slot], gShadowSamplers[SAMPLER_SHADOW]),
                   vec3(clamp(uv, r.lo, r.hi), depth));
}

float shadowDepthAt(ShadowRegion r, vec2 uv) {
    return textureLod(sampler2D(gTextures[r.slot], gSamplers[SAMPLER_NEAREST_CLAMP]),
                      clamp(uv, r.lo, r.hi), 0.0).r;
}

float pcf3x3(ShadowRegion r, vec2 uv, float depth) {
    float lit = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) lit += shadowCompare(r, uv + vec2(x, y) * r.texel, depth);
    return lit / 9.0;
}

float pcfDisk(ShadowRegion r, vec2 uv, float depth, float radiusTexels) {
    float lit = 0.0;
    for (int i = 0; i < 16; ++i)
        lit += shadowCompare(r, uv + kShadowDisk[i] * radiusTexels * r.texel, depth);
    return lit / 16.0;
}

// Mean stored depth of the taps nearer than `depth` within `radiusTexels`; x: mean, y: count.
vec2 shadowBlockerSearch(ShadowRegion r, vec2 uv, float depth, float radiusTexels) {
    float sum = 0.0, count = 0.0;
    for (int i = 0; i < 16; ++i) {
        float d = shadowDepthAt(r, uv + kShadowDisk[i] * radiusTexels * r.texel);
        if (d < depth) sum += d, count += 1.0;
    }
    return vec2(count > 0.0 ? sum / count : depth, count);
}

layout(buffer_reference, scalar) readonly buffer SunCascadesRef { GpuSunCascades c; };

// The sun's PCSS in an orthographic map region: texelWorld metres per texel, depth linear over
// depthRange metres.
float sunPcss(LightingFrame lf, ShadowRegion r, vec2 uv, float depth, float texelWorld,
              float depthRange) {
    // Occluders up to 8 m above the receiver can darken it: search the penumbra they cast.
    float search = clamp(lf.sunPenumbraScale * 8.0 / texelWorld, 1.0, 16.0);
    vec2 blockers = shadowBlockerSearch(r, uv, depth, search);
    if (blockers.y == 0.0) return 1.0; // nothing nearer the sun around: fully lit
    float penumbra = (depth - blockers.x) * depthRange * lf.sunPenumbraScale;
    return pcfDisk(r, uv, depth, clamp(penumbra / texelWorld, 1.0, 24.0));
}

// Cascaded sun shadows (render/lighting/sun_cascades.h): the first cascade whose view-depth
// slice holds the point filters its rectangle of the atlas, PCF (3x3) or PCSS, with a normal
// offset and depth bias of its own texel size. False (and `lit` unset) without cascades, or
// beyond the last one: the caller uses the map fitted to the whole scene.
bool sunCascadeShadow(FrameConstants f, vec3 worldPos, vec3 n, bool soft, out float lit) {
    lit = 1.0;
    if (f.lighting == 0ul) return false;
    LightingFrame lf = LightingFrameRef(f.lighting).l;
    if (lf.sunCascades == 0ul) return false;
    GpuSunCascades c = SunCascadesRef(lf.sunCascades).c;
    float viewDepth = dot(worldPos - f.cameraPosition, c.cameraForward);
    uint i = 0u;
    while (i < c.count && viewDepth > c.splitFar[i]) ++i;
    if (i >= c.count) return false;
    float texelWorld = c.texelWorld[i];
    vec3 p = worldPos + n * texelWorld * 1.5;
    vec3 ndc = (c.viewProj[i] * vec4(p, 1.0)).xyz; // orthographic: w = 1
    if (any(greaterThan(abs(ndc.xy), vec2(1.0))) || ndc.z > 1.0) return false;
    ShadowRegion r;
    r.slot = c.atlasSlot;
    r.texel = 1.0 / vec2(textureSize(gTextures[r.slot], 0));
    r.lo = c.atlasRect[i].xy + r.texel * 0.5;
    r.hi = c.atlasRect[i].xy + c.atlasRect[i].zw - r.texel * 0.5;
    vec2 uv = c.atlasRect[i].xy + (ndc.xy * 0.5 + 0.5) * c.atlasRect[i].zw;
    // Two texels of depth bias, in the cascade's depth units.
    float depth = ndc.z - 2.0 * texelWorld / c.depthRange;
    lit = soft ? sunPcss(lf, r, uv, depth, texelWorld, c.depthRange) : pcf3x3(r, uv, depth);
    return true;
}

// The sun: orthographic, depth linear over lf.sunDepthRange metres.
float sunShadowSoft(FrameConstants f, LightingFrame lf, vec3 worldPos, vec3 n) {
    if (f.sunShadowSlot == NO_TEXTURE) return 1.0;
    float cascaded;
    if (sunCascadeShadow(f, worldPos, n, true, cascaded)) return cascaded;
    vec3 p = worldPos + n * f.shadowTexelSize * 1.5;
    vec4 clip = f.sunViewProj * vec4(p, 1.0);
    vec3 ndc = clip.xyz / clip.w;
    vec2 uv = ndc.xy * 0.5 + 0.5;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || ndc.z > 1.0) return 1.0;
    float depth = ndc.z - 0.0015;
    ShadowRegion r;
    r.slot = f.sunShadowSlot;
    r.texel = 1.0 / vec2(textureSize(gTextures[f.sunShadowSlot], 0));
    r.lo = r.texel * 0.5;
    r.hi = 1.0 - r.texel * 0.5;
    // Occluders up to 8 m above the receiver can darken it: search the penumbra they cast.
    float search = clamp(lf.sunPenumbraScale * 8.0 / f.shadowTexelSize, 1.0, 16.0);
    vec2 blockers = shadowBlockerSearch(r, uv, depth, search);
    if (blockers.y == 0.0) return 1.0; // nothing nearer the sun around: fully lit
    float penumbra = (depth - blockers.x) * lf.sunDepthRange * lf.sunPenumbraScale;
    return pcfDisk(r, uv, depth, clamp(penumbra / f.shadowTexelSize, 1.0, 24.0));
}

// A spot with a map in the atlas: PCF, or PCSS with LIGHT_FLAG_SOFT_SHADOW (light.radius is
// the emitter's width).
float spotShadow(LightingFrame lf, GpuLight light, vec3 worldPos, vec3 n) {
    GpuSpotShadow s = SpotShadowBuffer(lf.spotShadows).s[light.shadowIndex];
    if (s.nearPlane < 0.0) return 1.0; // the atlas had no room for its map
    float distance = max(dot(worldPos - light.position, light.direction), s.nearPlane);
    // Normal offset of 1.5 texels at the receiver's distance keeps acne away.
    vec3 p = worldPos + n * (distance * s.texelAngle * 1.5);
    vec4 clip = s.viewProj * vec4(p, 1.0);
    if (clip.w <= 0.0) return 1.0;
    vec3 ndc = clip.xyz / clip.w;
    if (any(greaterThan(abs(ndc.xy), vec2(1.0))) || ndc.z > 1.0) return 1.0;
    ShadowRegion r;
    r.slot = lf.spotShadowAtlas;
    r.texel = 1.0 / vec2(textureSize(gTextures[r.slot], 0));
    r.lo = s.atlasRect.xy + r.texel * 0.5;
    r.hi = s.atlasRect.xy + s.atlasRect.zw - r.texel * 0.5;
    vec2 uv = s.atlasRect.xy + (ndc.xy * 0.5 + 0.5) * s.atlasRect.zw;
    float depth = ndc.z - 1e-5;
    if (!SPECTRUM_HAS(SPECTRUM_SOFT_SHADOWS) || (light.flags & LIGHT_FLAG_SOFT_SHADOW) == 0u)
        return pcf3x3(r, uv, depth);
    float receiver = clip.w; // view depth along the spot's axis
    float texelWorld = receiver * s.texelAngle;
    // An occluder halfway to the light casts a penumbra as wide as the emitter.
    float search = clamp(light.radius / texelWorld, 1.0, 16.0);
    vec2 blockers = shadowBlockerSearch(r, uv, depth, search);
    if (blockers.y == 0.0) return 1.0;
    float n0 = s.nearPlane, f0 = s.farPlane;
    float blocker = n0 * f0 / (f0 - blockers.x * (f0 - n0)); // linear depth of the mean
    float penumbra = light.radius * max(receiver - blocker, 0.0) / max(blocker, 1e-3);
    return pcfDisk(r, uv, depth, clamp(penumbra / texelWorld, 1.0, 24.0));
}
#endif
