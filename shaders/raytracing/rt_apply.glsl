// Hands the ray-traced terms to the shared lighting code (gRtOcclusion and the other globals of
// common/lighting.glsl). Forward path: the pixel's ray-traced terms (written by rt_pixel.frag, the
// pass before forward shading) to the shared lighting code (gRtOcclusion and the other globals of
// common/lighting.glsl). AO, indirect light and soft shadows are noisy per pixel (a few rays each),
// so they are read through a small depth-aware 3x3 filter; hard shadows are exact and read as they
// are.
#ifndef SHADEL_RT_APPLY_GLSL
#define SHADEL_RT_APPLY_GLSL
#include "common/lighting.glsl"
#include "raytracing/rt_frame.glsl"

// Per-spot sums over `weight` samples, packed back into 8 bits each.
uvec4 rtPackSpotMeans(float sum[LIGHT_MAX_SPOT_SHADOWS], float weight, uint count) {
    uvec4 packed = uvec4(0xFFFFFFFFu);
    for (uint k = 0u; k < count; ++k) {
        uint shift = (k & 3u) * 8u;
        uint q = uint(round(clamp(sum[k] / weight, 0.0, 1.0) * 255.0));
        packed[k >> 2u] = (packed[k >> 2u] & ~(0xFFu << shift)) | (q << shift);
    }
    return packed;
}

// The filter's taps: a 3x3 neighbour q whose traced surface is the centre's (view distance
// within 3%); its terms in t.
bool rtFilterTap(uint termsSlot, ivec2 q, vec4 centre, out vec4 t) {
    t = texelFetch(gTextures[termsSlot], q, 0);
    return t.w > 0.0 && abs(t.w - centre.w) <= 0.03 * centre.w;
}

void useRayTracedPixelTerms(FrameConstants f, vec2 fragCoord) {
    if (f.rt == 0ul) return;
    RtFrame rt = RtFrameRef(f.rt).r;
    if (rt.pixelTermsSlot == NO_TEXTURE) return;
    ivec2 p = ivec2(fragCoord);
    ivec2 size = textureSize(gTextures[rt.pixelTermsSlot], 0);
    vec4 centre = texelFetch(gTextures[rt.pixelTermsSlot], p, 0); // sun, AO, -, view distance
    if (centre.w <= 0.0) return; // nothing traced here (not an opaque surface)
    vec4 terms = centre;
    vec3 indirect = rt.gi != 0u ? texelFetch(gTextures[rt.pixelIndirectSlot], p, 0).rgb : vec3(0.0);
    // Soft spot shadows are as noisy as the sun's: filtered with the same taps.
    bool filterSpots = rt.spatialFilter != 0u && rt.spotShadowCount != 0u && rt.shadowRays > 1u;
    float spotSum[LIGHT_MAX_SPOT_SHADOWS];
    for (uint k = 0u; k < rt.spotShadowCount && filterSpots; ++k) spotSum[k] = 0.0;
    float weight = 0.0;
    if (rt.spatialFilter != 0u) {
        vec4 sum = vec4(0.0);
        vec3 indirectSum = vec3(0.0);
        for (int y = -1; y <= 1; ++y)
            for (int x = -1; x <= 1; ++x) {
                ivec2 q = clamp(p + ivec2(x, y), ivec2(0), size - 1);
                vec4 t;
                if (!rtFilterTap(rt.pixelTermsSlot, q, centre, t)) continue;
                sum += t;
                if (rt.gi != 0u) indirectSum += texelFetch(gTextures[rt.pixelIndirectSlot], q, 0).rgb;
                if (filterSpots) {
                    uvec4 v = texelFetch(gUTextures[rt.pixelSpotSlot], q, 0);
                    for (uint k = 0u; k < rt.spotShadowCount; ++k) spotSum[k] += rtSpotVisibility(v, k);
                }
                weight += 1.0;
            }
        terms.y = sum.y / weight; // the centre always passes
        if (rt.shadowRays > 1u) terms.x = sum.x / weight;
        indirect = indirectSum / weight;
    }
    if (rt.spotShadowCount != 0u) {
        gRtSpots = true;
        gRtSpotVisibility = filterSpots ? rtPackSpotMeans(spotSum, weight, rt.spotShadowCount)
                                        : texelFetch(gUTextures[rt.pixelSpotSlot], p, 0);
    }
    gRtSun = rt.shadows != 0u;
    gRtSunVisibility = terms.x;
    gRtOcclusion = rt.ao != 0u ? terms.y : 1.0;
    gRtIndirect = indirect;
}

// Shadel path: the object's RT cache (rt_shadels.comp), read bilinearly at the shadel's UV in
// the object's shadel space (texels with no surface are left out of the filter). While those
// texels hold few rays (new in view, or reset) the noisy terms (AO, GI, soft sun) also pool the
// rays of the 4x4 texels around (a tent two texels wide, each texel weighted by its rays, texels
// of another surface left out), blended out as the bilinear texels reach RT_SHADEL_FILTER_RAYS:
// what the forward path's 3x3 filter does per pixel, here only until the history holds enough.
void useRayTracedShadelTerms(FrameConstants f, uint object, vec2 shadelUv) {
    if (f.rt == 0ul) return;
    RtFrame rt = RtFrameRef(f.rt).r;
    if (rt.shadelObjects == 0ul) return;
    RtShadelObject o = RtShadelObjectRefs(rt.shadelObjects).o[object];
    if ((o.flags & RT_SHADEL_VALID) == 0u) return;
    vec2 t = clamp(shadelUv * vec2(o.size) - 0.5, vec2(0.0), vec2(o.size) - 1.0);
    ivec2 t0 = ivec2(floor(t));
    vec2 fr = t - vec2(t0);
    vec4 terms = vec4(0.0); // sun, AO, -, rays
    vec3 indirect = vec3(0.0);
    vec3 normalSum = vec3(0.0);
    float spots[LIGHT_MAX_SPOT_SHADOWS];
    for (uint j = 0u; j < rt.spotShadowCount; ++j) spots[j] = 0.0;
    float weight = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 d = ivec2(k & 1, k >> 1);
        ivec2 q = ivec2(o.origin) + min(t0 + d, ivec2(o.size) - 1);
        vec4 v = texelFetch(gTextures[rt.shadelTermsRead], q, 0);
        float w = (d.x == 1 ? fr.x : 1.0 - fr.x) * (d.y == 1 ? fr.y : 1.0 - fr.y);
        if (v.w <= 0.0) continue; // no surface there
        vec4 ind = texelFetch(gTextures[rt.shadelIndirectRead], q, 0);
        terms += v * w;
        indirect += ind.rgb * w;
        normalSum += rtOctDecode(vec2(v.z, ind.w)) * w;
        if (rt.spotShadowCount != 0u) {
            uvec4 sv = texelFetch(gUTextures[rt.shadelSpotRead], q, 0);
            for (uint j = 0u; j < rt.spotShadowCount; ++j) spots[j] += rtSpotVisibility(sv, j) * w;
        }
        weight += w;
    }
    // No rays under the bilinear taps yet (texels waiting their turn, rt_shadels.comp): the
    // pooled neighbours alone.
    bool traced = weight > 0.0;
    terms = traced ? terms / weight : vec4(1.0, 1.0, 0.0, 0.0);
    indirect = traced ? indirect / weight : vec3(0.0);
    // Few rays yet: the rays of the same surface around, pooled.
    float history = clamp(terms.w / RT_SHADEL_FILTER_RAYS, 0.0, 1.0);
    if (history < 1.0) {
        // The surface: the bilinear taps' normal, or with none traced, the nearest texel's.
        vec3 centreNormal = normalSum;
        if (!traced) {
            ivec2 q = ivec2(o.origin) + clamp(ivec2(round(t)), ivec2(0), ivec2(o.size) - 1);
            centreNormal = rtOctDecode(vec2(texelFetch(gTextures[rt.shadelTermsRead], q, 0).z,
                                            texelFetch(gTextures[rt.shadelIndirectRead], q, 0).w));
        }
        centreNormal = normalize(centreNormal);
        vec3 pooled = vec3(0.0); // sun, AO, rays
        vec3 pooledIndirect = vec3(0.0);
        for (int y = -1; y <= 2; ++y)
            for (int x = -1; x <= 2; ++x) {
                ivec2 c = t0 + ivec2(x, y);
                if (any(lessThan(c, ivec2(0))) || any(greaterThanEqual(c, ivec2(o.size)))) continue;
                vec2 tent = max(1.0 - abs(vec2(c) - t) * 0.5, vec2(0.0));
                ivec2 q = ivec2(o.origin) + c;
                vec4 v = texelFetch(gTextures[rt.shadelTermsRead], q, 0);
                if (v.w <= 0.0) continue;
                vec4 ind = texelFetch(gTextures[rt.shadelIndirectRead], q, 0);
                if (dot(rtOctDecode(vec2(v.z, ind.w)), centreNormal) < 0.9) continue;
                float w = tent.x * tent.y * v.w;
                pooled += vec3(v.xy, 1.0) * w;
                pooledIndirect += ind.rgb * w;
            }
        if (!traced && pooled.z <= 0.0) return; // nothing traced around yet
        if (pooled.z > 0.0) {
            terms.y = mix(pooled.y / pooled.z, terms.y, history);
            if (rt.shadowRays > 1u || !traced) terms.x = mix(pooled.x / pooled.z, terms.x, history);
            indirect = mix(pooledIndirect / pooled.z, indirect, history);
        }
    }
    if (rt.spotShadowCount != 0u && traced) {
        gRtSpots = true;
        gRtSpotVisibility = rtPackSpotMeans(spots, weight, rt.spotShadowCount);
    }
    gRtSun = rt.shadows != 0u;
    gRtSunVisibility = terms.x;
    gRtOcclusion = rt.ao != 0u ? terms.y : 1.0;
    gRtIndirect = indirect;
}
#endif
