// Decoupled reuse with ray-traced terms: a chunk carried over keeps the RT terms (AO, GI, soft
// shadows) it was shaded with, while the RT cache under it (rt_shadels.comp) keeps adding rays,
// so a carried image would trail the cache by up to the refresh period. Instead a carried chunk
// is reshaded each time the cache's ray count under it passes a step: at 1, 1.41, 2, 2.83, 4, ...
// rays (powers of RT_HISTORY_STEP = sqrt 2), times a per-chunk factor in [1, RT_HISTORY_STEP) so
// the reshades of a still view spread over frames instead of all landing on the same frame. What
// a carried chunk shows then holds at least 71% of the rays the cache holds, and the reshades
// cost O(log rays) per chunk, not one per frame.
#ifndef SHADEL_RT_HISTORY_GLSL
#define SHADEL_RT_HISTORY_GLSL
#include "raytracing/rt_frame.glsl"

// Each threshold is RT_HISTORY_STEP times the last. Measured (builtin:default 320x180, a still
// camera, AO, 16 frames, PSNR per frame against a 256-ray render): reuse off 34.6 / 39.7 / 46.4
// dB at frames 1 / 3 / 15; carrying RT terms over until the refresh 27.8 / 28.9 / 45.0 (reuse
// 0.874); steps of 2: 34.5 / 37.6 / 45.6 (reuse 0.650); steps of sqrt 2: 34.5 / 38.0 / 45.5
// (reuse 0.488). Those were with --reuse-refresh 8, whose round robin also reshaded every chunk
// within 8 frames. Since the refresh is 16 (chunks now follow their own view), the round robin
// no longer hides the steps' lag: the still-camera AO at 96x54 after 16 frames
// (RayTracing.ShadelAoConvergesToTheHighRayReference) gave 34.17 dB with steps of 2 and 35.75 dB
// with steps of sqrt 2 (a carried chunk then shows at least 71% of the cache's rays).
const float RT_HISTORY_STEP = 1.41421356;

// Whether the cache texel at `shadelUv` of `object` crossed one of the chunk's thresholds with
// this frame's rays (rt_shadels.comp ran before; a texel traced this frame holds `rays` more).
// `phase` in [1, RT_HISTORY_STEP): the chunk's thresholds are phase * RT_HISTORY_STEP^j.
bool rtTexelHistoryStepped(RtFrame rt, RtShadelObject o, vec2 shadelUv, float phase) {
    ivec2 t = clamp(ivec2(shadelUv * vec2(o.size)), ivec2(0), ivec2(o.size) - 1);
    float count = texelFetch(gTextures[rt.shadelTermsRead], ivec2(o.origin) + t, 0).w;
    // No surface, or converged (no more rays are traced: the count no longer moves).
    if (count <= 0.0 || count >= float(rt.historyRays)) return false;
    // The largest threshold at or below the count, and whether this frame's rays reached it.
    // (A threshold between two counts is reached at the higher: ceil.)
    float steps = floor(log2(count / phase) / log2(RT_HISTORY_STEP) + 1e-4);
    float threshold = max(ceil(exp2(steps * log2(RT_HISTORY_STEP)) * phase - 1e-3), 1.0);
    return threshold > count - float(rt.raysPerShadel);
}

// Whether a carried chunk of `object` must be reshaded for its RT terms. `uvs`: four points of
// the chunk in the object's shadel UV (the cache's texels are coarser than the chunk's shadels,
// mostly a few per chunk); `chunkKey` spreads the chunks' thresholds.
bool rtHistoryStepped(FrameConstants f, uint object, vec2 uvs[4], uint chunkKey) {
    if (f.rt == 0ul) return false;
    RtFrame rt = RtFrameRef(f.rt).r;
    // Hard shadows alone are exact from a texel's first ray: nothing converges.
    bool converging = rt.ao != 0u || rt.gi != 0u || (rt.shadows != 0u && rt.shadowRays > 1u) ||
                      (rt.spotShadowCount != 0u && rt.shadowRays > 1u);
    if (rt.shadelObjects == 0ul || !converging) return false;
    RtShadelObject o = RtShadelObjectRefs(rt.shadelObjects).o[object];
    if ((o.flags & RT_SHADEL_VALID) == 0u) return false;
    float phase = exp2(log2(RT_HISTORY_STEP) * float((chunkKey * 2654435761u >> 13) & 7u) / 8.0);
    bool stepped = false;
    for (int i = 0; i < 4; ++i) stepped = stepped || rtTexelHistoryStepped(rt, o, uvs[i], phase);
    return stepped;
}
#endif
