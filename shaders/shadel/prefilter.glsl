// Prefiltered material in shadel space (issue 8): a shadel stands for its whole footprint on the
// surface (2^k x 2^k MIP-0 shadels at MIP k, and at MIP 0 itself whatever the density makes it).
// Textures are already filtered by that footprint (the UV derivatives come from neighbouring
// shadels); point-function procedurals (the one-texel checker, bricks) have no filtered form,
// so they are supersampled: n x n stratified samples, n in proportion to how many pattern cells
// the footprint spans (two samples per cell), capped at sqrt(maxSamples). The jitter is a hash of
// the shadel, so every frame shades the same samples (no flicker). Lighting runs once, at the
// centre. Normals are averaged unnormalised: a short mean normal means the normals under the
// footprint vary, and Toksvig's factor widens the specular lobe (toksvigRoughness), so specular
// does not alias either. Forward and shadel paths share evaluateMaterial (shaders/common).
#ifndef SHADEL_PREFILTER_GLSL
#define SHADEL_PREFILTER_GLSL
#include "common/material.glsl"
#include "common/shadel_bary.h"

// Pattern cells per UV unit of the procedural (0: no procedural, the material needs no samples).
float proceduralFrequency(GpuMaterial m) {
    if (m.procedural == PROCEDURAL_TEXEL_CHECKER) return m.proceduralScale;
    if (m.procedural == PROCEDURAL_BRICKS) return 2.0 * m.proceduralScale; // two rows per unit
    return 0.0;
}

uint prefilterHash(uvec3 v) {
    uint h = v.x * 0x8da6b343u ^ v.y * 0xd8163841u ^ v.z * 0xcb1ab31fu;
    h ^= h >> 16; h *= 0x7feb352du; h ^= h >> 15; h *= 0x846ca68bu; h ^= h >> 16;
    return h;
}

// si: the surface at the shadel centre (uv derivatives = one shadel of this level). centre/step:
// the shadel's centre and size in the object's shadel UV; s0..s2 the triangle's shadel UVs and
// t0..t2 its material UVs; seed identifies the shadel.
MaterialSample prefilteredMaterial(GpuMaterial mat, SurfaceInput si, vec2 centre, vec2 step,
                                   vec2 s0, vec2 s1, vec2 s2, vec2 t0, vec2 t1, vec2 t2,
                                   uint maxSamples, uvec3 seed) {
    float cells = proceduralFrequency(mat) * max(length(si.uvDx), length(si.uvDy));
    uint cap = uint(floor(sqrt(float(max(maxSamples, 1u)) + 1e-3)));
    uint n = uint(clamp(ceil(2.0 * cells), 1.0, float(cap)));
    if (n <= 1u) return evaluateMaterial(mat, si);
    MaterialSample sum;
    sum.baseColor = vec3(0.0); sum.alpha = 0.0; sum.normal = vec3(0.0); sum.metallic = 0.0;
    sum.roughness = 0.0; sum.occlusion = 0.0; sum.emissive = vec3(0.0);
    SurfaceInput sub = si;
    sub.uvDx = si.uvDx / float(n);
    sub.uvDy = si.uvDy / float(n);
    uint h = prefilterHash(seed);
    for (uint j = 0u; j < n; ++j) {
        for (uint i = 0u; i < n; ++i) {
            h = h * 747796405u + 2891336453u;
            vec2 jitter = vec2(float(h & 0xFFFFu), float(h >> 16)) / 65536.0;
            vec2 at = centre + ((vec2(i, j) + jitter) / float(n) - 0.5) * step;
            vec3 b = shadelBarycentrics(at, s0, s1, s2);
            sub.uv = shadelInterpolate2(b, t0, t1, t2);
            MaterialSample one = evaluateMaterial(mat, sub);
            sum.baseColor += one.baseColor; sum.alpha += one.alpha; sum.normal += one.normal;
            sum.metallic += one.metallic; sum.roughness += one.roughness;
            sum.occlusion += one.occlusion; sum.emissive += one.emissive;
        }
    }
    float w = 1.0 / float(n * n);
    MaterialSample m;
    m.baseColor = sum.baseColor * w; m.alpha = sum.alpha * w;
    m.normal = normalize(sum.normal); m.metallic = sum.metallic * w;
    m.roughness = toksvigRoughness(sum.roughness * w, length(sum.normal) * w);
    m.occlusion = sum.occlusion * w; m.emissive = sum.emissive * w;
    return m;
}
#endif
