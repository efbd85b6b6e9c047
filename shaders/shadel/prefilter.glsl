// Prefiltered material in shadel space: a shadel stands for its whole footprint on the
// surface (2^k x 2^k MIP-0 shadels at MIP k, and at MIP 0 itself whatever the density makes it).
// Textures are already filtered by that footprint (the UV derivatives come from neighbouring
// shadels); point-function procedurals (the one-texel checker, bricks) have no filtered form,
// so they are supersampled: n x n stratified samples, n in proportion to how many pattern cells
// the footprint spans (two samples per cell), capped at sqrt(maxSamples). The jitter is a hash of
// the shadel, so every frame shades the same samples (no flicker). Lighting runs at the centre
// (twice when supersampled, see prefilteredShade; the sun's shadow is sampled once). Normals are averaged unnormalised: a short mean normal means the normals under the
// footprint vary, and Toksvig's factor widens the specular lobe (toksvigRoughness), so specular
// does not alias either. Forward and shadel paths share evaluateMaterial (shaders/common).
#ifndef SHADEL_PREFILTER_GLSL
#define SHADEL_PREFILTER_GLSL
#include "common/lighting.glsl"
#include "common/tone_curve.glsl"
#include "common/shadel_bary.h"

// Pattern cells per UV unit of the procedural (0: no procedural, the material needs no samples).
float proceduralFrequency(GpuMaterial m) {
    if (m.procedural == PROCEDURAL_TEXEL_CHECKER) return m.proceduralScale;
    if (m.procedural == PROCEDURAL_BRICKS) return 2.0 * m.proceduralScale; // two rows per unit
    return 0.0;
}

#define PREFILTER_KEPT_SAMPLES 16u // base colours prefilteredShade keeps between its passes

uint prefilterHash(uvec3 v) {
    uint h = v.x * 0x8da6b343u ^ v.y * 0xd8163841u ^ v.z * 0xcb1ab31fu;
    h ^= h >> 16; h *= 0x7feb352du; h ^= h >> 15; h *= 0x846ca68bu; h ^= h >> 16;
    return h;
}

// Sub-sample (i, j) of n x n: its surface input (uv and footprint), advancing the jitter state h.
SurfaceInput prefilterSample(SurfaceInput si, uint i, uint j, uint n, inout uint h, vec2 centre,
                             vec2 step, vec2 s0, vec2 s1, vec2 s2, vec2 t0, vec2 t1, vec2 t2) {
    h = h * 747796405u + 2891336453u;
    vec2 jitter = vec2(float(h & 0xFFFFu), float(h >> 16)) / 65536.0;
    vec2 offset = (vec2(i, j) + jitter) / float(n) - 0.5; // in shadels from the centre
    vec2 at = centre + offset * step;
    SurfaceInput sub = si;
    sub.uv = clampToTriangleUv(shadelInterpolate2(shadelBarycentrics(at, s0, s1, s2), t0, t1, t2),
                               t0, t1, t2);
    sub.uvDx = si.uvDx / float(n);
    sub.uvDy = si.uvDy / float(n);
    // The second UV set is affine over the triangle too: its shadel derivatives carry it.
    sub.uv1 = si.uv1 + si.uv1Dx * offset.x + si.uv1Dy * offset.y;
    sub.uv1Dx = si.uv1Dx / float(n);
    sub.uv1Dy = si.uv1Dy / float(n);
    return sub;
}

// The shaded colour of one shadel: its material prefiltered over the footprint, lit once.
// si: the surface at the shadel centre (uv derivatives = one shadel of this level). centre/step:
// the shadel's centre and size in the object's shadel UV; s0..s2 the triangle's shadel UVs and
// t0..t2 its material UVs; seed identifies the shadel.
//
// Where the resolve averages: the supersampled reference averages pixels after the tone curve,
// so a bright/dark pattern averaged in linear light comes out too bright. Lighting is affine in
// the base colour (exactly for dielectrics), so it runs twice (base 0 and 1, with the averaged
// normal, roughness, metallic) and each sample's colour is rebuilt from its base colour, put
// through the tone curve, averaged, and mapped back: the shadel then displays as the average of
// its samples would. `material` receives the prefiltered base colour and roughness (the shade
// storage's material layer).
vec3 prefilteredShade(FrameConstants f, GpuMaterial mat, SurfaceInput si, vec2 centre, vec2 step,
                      vec2 s0, vec2 s1, vec2 s2, vec2 t0, vec2 t1, vec2 t2, uint maxSamples,
                      uvec3 seed, out vec4 material) {
    float cells = proceduralFrequency(mat) * max(length(si.uvDx), length(si.uvDy));
    uint cap = uint(floor(sqrt(float(max(maxSamples, 1u)) + 1e-3)));
    uint n = uint(clamp(ceil(2.0 * cells), 1.0, float(cap)));
    // kShadeQueue (shade.comp): only the supersampled class (and the spectra's all-in-one
    // permutations) have the supersampling compiled in, and only with procedurals (the spectra's
    // permutations without material features have none: n is 1).
    if (n <= 1u || (kShadeQueue != SHADE_QUEUE_SUPERSAMPLED && kShadeQueue != SHADE_QUEUE_ALL) ||
        !MATERIAL_HAS(MATERIAL_FEATURE_PROCEDURAL)) {
        MaterialSample one = evaluateMaterial(mat, si);
        material = vec4(clamp(one.baseColor, 0.0, 1.0), one.roughness);
        return shadeSurface(f, one, si.position, si.normal);
    }
    MaterialSample sum;
    sum.baseColor = vec3(0.0); sum.alpha = 0.0; sum.normal = vec3(0.0); sum.metallic = 0.0;
    sum.roughness = 0.0; sum.occlusion = 0.0; sum.emissive = vec3(0.0);
    uint h = prefilterHash(seed);
    MaterialSample last;
    // The samples' base colours, kept for the display pass below when they fit (n <= 4: every
    // n of the default --material-samples 16); more samples are evaluated again there.
    vec3 bases[PREFILTER_KEPT_SAMPLES];
    bool keep = n * n <= PREFILTER_KEPT_SAMPLES;
    for (uint j = 0u; j < n; ++j) {
        for (uint i = 0u; i < n; ++i) {
            SurfaceInput sub = prefilterSample(si, i, j, n, h, centre, step, s0, s1, s2, t0, t1, t2);
            MaterialSample one = evaluateMaterial(mat, sub);
            if (keep) bases[j * n + i] = one.baseColor;
            last = one;
            sum.baseColor += one.baseColor; sum.alpha += one.alpha; sum.normal += one.normal;
            sum.metallic += one.metallic; sum.roughness += one.roughness;
            sum.occlusion += one.occlusion; sum.emissive += one.emissive;
        }
    }
    float w = 1.0 / float(n * n);
    // Only procedural materials are supersampled: their extension terms (factors) are the same
    // in every sample, the last one carries them.
    MaterialSample m = last;
    m.alpha = sum.alpha * w;
    m.normal = normalize(sum.normal); m.metallic = sum.metallic * w;
    m.roughness = toksvigRoughness(sum.roughness * w, length(sum.normal) * w);
    m.occlusion = sum.occlusion * w; m.emissive = sum.emissive * w;
    material = vec4(clamp(sum.baseColor * w, 0.0, 1.0), m.roughness);
    m.baseColor = vec3(0.0);
    vec3 c0 = shadeSurface(f, m, si.position, si.normal);
    // The second pass lights the same point: it takes the first's sun visibility as a given
    // one (as ray-traced visibility is given) rather than sampling the shadow map again: the
    // same value, so the same colour, without the shadow taps.
    bool givenSun = gRtSun;
    float givenSunVisibility = gRtSunVisibility;
    gRtSun = true;
    gRtSunVisibility = gSunVisibilityUsed;
    m.baseColor = vec3(1.0);
    vec3 c1 = shadeSurface(f, m, si.position, si.normal);
    gRtSun = givenSun;
    gRtSunVisibility = givenSunVisibility;
    float exposure = max(f.exposure, 1e-6);
    vec3 display = vec3(0.0);
    h = prefilterHash(seed); // the same samples again (when not kept)
    for (uint j = 0u; j < n; ++j) {
        for (uint i = 0u; i < n; ++i) {
            vec3 base = keep ? bases[j * n + i]
                             : evaluateMaterial(mat, prefilterSample(si, i, j, n, h, centre, step,
                                                                     s0, s1, s2, t0, t1, t2))
                                   .baseColor;
            display += acesFit(max(c0 + base * (c1 - c0), vec3(0.0)) * exposure);
        }
    }
    return acesFitInverse(display * w) / exposure;
}
#endif
