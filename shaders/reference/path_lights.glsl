// Next-event estimation of the reference path tracer: at every surface a path reaches, the light
// each source sends it, through the shared BRDF (common/lighting.glsl brdf, evaluateLight) and
// a shadow ray. The sun and the buffer's directional, point and spot lights are deltas: one ray
// each, no other way to reach them. Tube and area lights are lit as the raster path lights them
// (their representative point, evaluateLight) with one shadow ray to their centre: not exact
// for them. The environment is sampled with cosine-weighted directions about the shading normal
// and weighted against the BRDF samples that escape to it (balance heuristic); a path's last
// surface takes the environment from its cosine sample alone.
#ifndef SHADEL_PATH_LIGHTS_GLSL
#define SHADEL_PATH_LIGHTS_GLSL
#include "reference/path_random.glsl"
#include "reference/path_sampling.glsl"
#include "reference/path_visibility.glsl"

// The environment's radiance along d (the background map, without the sun's disc: the sun is a
// light of its own).
vec3 environmentRadiance(GpuEnvironment e, vec3 d) {
    if ((e.flags & ENVIRONMENT_FLAG_NONE) != 0u) return vec3(0.0);
    vec2 uv = environmentUv(environmentFrame(e, d));
    return e.intensity * environmentFetch(e.backgroundSlot, uv, 0.0, e.backgroundHeight);
}

bool hasEnvironment(GpuEnvironment e) { return (e.flags & ENVIRONMENT_FLAG_NONE) == 0u; }

struct PathVertex {
    vec3 position;
    vec3 geometricNormal; // on the side the path arrived from
    vec3 normal;          // shading, on that side
    vec3 view;            // toward where the path came from
};

// Shadow rays leave along the geometric normal on the side they go.
vec3 pathRayOrigin(FrameConstants f, RtFrame rt, PathVertex x, vec3 dir) {
    return rtOrigin(f, rt, x.position, x.geometricNormal, dir);
}

vec3 directLights(FrameConstants f, RtFrame rt, MaterialSample m, PathVertex x, bool alpha,
                  inout uint rays) {
    vec3 sum = vec3(0.0);
    vec3 toSun = -f.sunDirection;
    if (dot(f.sunColor, f.sunColor) > 0.0 && dot(x.normal, toSun) > 0.0) {
        ++rays;
        if (!pathOccluded(f, rt, pathRayOrigin(f, rt, x, toSun), toSun, 1e30, alpha, gPathRandom))
            sum += brdf(m, x.normal, x.view, toSun, f.sunColor);
    }
    LightBuffer lights = LightBuffer(f.lights);
    for (uint i = 0u; i < f.lightCount; ++i) {
        GpuLight light = lights.l[i];
        vec3 lit = max(evaluateLight(light, m, x.normal, x.view, x.position), vec3(0.0));
        if (all(equal(lit, vec3(0.0)))) continue; // no light here: no ray
        vec3 dir = -light.direction;
        float tMax = 1e30;
        if (light.type != LIGHT_DIRECTIONAL) {
            vec3 toLight = light.position - x.position;
            tMax = length(toLight) * 0.999; // a lamp's own surface does not shadow its light
            dir = toLight / max(length(toLight), 1e-6);
        }
        ++rays;
        if (!pathOccluded(f, rt, pathRayOrigin(f, rt, x, dir), dir, tMax, alpha, gPathRandom))
            sum += lit;
    }
    return sum;
}

// The environment through one cosine-weighted direction (`last`: the path ends here, so no BRDF
// sample will reach the environment from this surface and the weight is 1).
vec3 directEnvironment(FrameConstants f, RtFrame rt, MaterialSample m, PathVertex x,
                       float specularChance, bool last, bool alpha, inout uint rays) {
    if (!hasEnvironment(f.environment)) return vec3(0.0);
    vec3 dir = rtCosineDirection(x.normal, pathRandom2());
    float pdf = max(dot(x.normal, dir), 0.0) / PI;
    if (pdf <= 1e-8) return vec3(0.0);
    vec3 reflected = brdf(m, x.normal, x.view, dir, environmentRadiance(f.environment, dir));
    if (all(equal(reflected, vec3(0.0)))) return vec3(0.0);
    ++rays;
    if (pathOccluded(f, rt, pathRayOrigin(f, rt, x, dir), dir, 1e30, alpha, gPathRandom))
        return vec3(0.0);
    float weight =
        last ? 1.0 : balanceWeight(pdf, brdfSamplePdf(m, x.normal, x.view, dir, specularChance));
    return reflected * (weight / pdf);
}
#endif
