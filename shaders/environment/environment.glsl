// Image-based lighting reads (render/environment): the prefiltered specular chain, the
// irradiance, the background and the split-sum BRDF table, each applying the environment's
// rotation and intensity. Every lookup is textureLod with an explicit level (no derivatives:
// callable from compute and from any control flow); u wraps at the seam, v is kept inside the
// level's first and last rows' texel centres so the poles never blend with the other pole.
#ifndef SHADEL_ENVIRONMENT_GLSL
#define SHADEL_ENVIRONMENT_GLSL

#include "common/bindless.glsl"
#include "common/shared_types.h" // GpuEnvironment

#ifndef PI
#define ENVIRONMENT_PI 3.14159265358979
#else
#define ENVIRONMENT_PI PI
#endif

vec3 environmentFrame(GpuEnvironment e, vec3 d) {
    return vec3(e.rotationCos * d.x + e.rotationSin * d.z, d.y,
                -e.rotationSin * d.x + e.rotationCos * d.z);
}

// The equirectangular coordinates of a direction in the environment's frame (equirect.h).
vec2 environmentUv(vec3 d) {
    d = normalize(d);
    float u = abs(d.x) + abs(d.z) > 1e-12 ? 0.5 + atan(-d.x, d.z) / (2.0 * ENVIRONMENT_PI) : 0.5;
    float v = acos(clamp(d.y, -1.0, 1.0)) / ENVIRONMENT_PI;
    return vec2(u, v);
}

// One MIP level of an equirectangular map `rows` texel rows high at that level.
vec3 environmentFetch(uint slot, vec2 uv, float level, float rows) {
    uv.y = clamp(uv.y, 0.5 / rows, 1.0 - 0.5 / rows);
    return sampleTextureLod(slot, SAMPLER_LINEAR_REPEAT, uv, level).rgb;
}

// Irradiance / pi around the normal n: times a Lambert albedo, the diffuse radiance.
vec3 environmentIrradiance(GpuEnvironment e, vec3 n) {
    if ((e.flags & ENVIRONMENT_FLAG_NONE) != 0u) return vec3(0.0);
    vec2 uv = environmentUv(environmentFrame(e, n));
    return e.intensity * environmentFetch(e.irradianceSlot, uv, 0.0, e.irradianceHeight);
}

// Radiance around the reflection direction r prefiltered for a GGX lobe of perceptual
// roughness (lod = roughness x (levels - 1)), blending the two nearest levels.
vec3 environmentSpecular(GpuEnvironment e, vec3 r, float perceptualRoughness) {
    if ((e.flags & ENVIRONMENT_FLAG_NONE) != 0u) return vec3(0.0);
    vec2 uv = environmentUv(environmentFrame(e, r));
    float top = float(e.specularLevels - 1u);
    float lod = clamp(perceptualRoughness, 0.0, 1.0) * top;
    float l0 = floor(lod), l1 = min(l0 + 1.0, top);
    vec3 a = environmentFetch(e.specularSlot, uv, l0, max(floor(e.specularHeight / exp2(l0)), 1.0));
    vec3 b = environmentFetch(e.specularSlot, uv, l1, max(floor(e.specularHeight / exp2(l1)), 1.0));
    return e.intensity * mix(a, b, lod - l0);
}

// Radiance around r prefiltered for the Charlie (sheen) lobe of `sheenRoughness`, as
// environmentSpecular does for GGX.
vec3 environmentSheen(GpuEnvironment e, vec3 r, float sheenRoughness) {
    if ((e.flags & ENVIRONMENT_FLAG_NONE) != 0u || e.sheenLevels == 0u) return vec3(0.0);
    vec2 uv = environmentUv(environmentFrame(e, r));
    float top = float(e.sheenLevels - 1u);
    float lod = clamp(sheenRoughness, 0.0, 1.0) * top;
    float l0 = floor(lod), l1 = min(l0 + 1.0, top);
    vec3 a = environmentFetch(e.sheenSlot, uv, l0, max(floor(e.sheenHeight / exp2(l0)), 1.0));
    vec3 b = environmentFetch(e.sheenSlot, uv, l1, max(floor(e.sheenHeight / exp2(l1)), 1.0));
    return e.intensity * mix(a, b, lod - l0);
}

// What the camera sees along viewDir (from the eye outward), with the sun's disc.
vec3 environmentBackground(GpuEnvironment e, vec3 viewDir) {
    if ((e.flags & ENVIRONMENT_FLAG_NONE) != 0u) return vec3(0.0);
    vec3 d = normalize(environmentFrame(e, viewDir));
    vec3 radiance = environmentFetch(e.backgroundSlot, environmentUv(d), 0.0, e.backgroundHeight);
    if ((e.flags & ENVIRONMENT_FLAG_SUN_DISC) != 0u && dot(d, -e.sunDirection) > e.sunCosRadius)
        radiance += e.sunRadiance;
    return e.intensity * radiance;
}

// The split-sum table at (n.v, perceptual roughness): x = scale and y = bias of F0 in the
// specular's directional albedo (F0 * x + F90 * y), z = the Charlie sheen's directional albedo
// (at sheen roughness; above 1 at grazing views of smooth sheen). Valid with no environment.
vec3 environmentBrdf(GpuEnvironment e, float nv, float perceptualRoughness) {
    float half_ = 0.5 / e.brdfSize;
    vec2 uv = clamp(vec2(nv, perceptualRoughness), vec2(half_), vec2(1.0 - half_));
    return sampleTextureLod(e.brdfSlot, SAMPLER_LINEAR_REPEAT, uv, 0.0).rgb;
}

#endif
