#version 460
// The reference path tracer (render/reference): one thread per pixel of the internal
// resolution traces ReferencePush::samples paths and folds their mean into the accumulated one.
// A path starts at a uniformly jittered point of the pixel (the pixel's box filter: antialiased
// as the mean converges); at every surface it hits it adds the emission (when the first hit, or
// reached by a BRDF sample: no light source samples emitting surfaces, so no weighting is
// needed), the lights and the environment by next-event estimation (reference/path_lights.glsl),
// then continues along a BRDF sample (reference/path_sampling.glsl) with throughput
// brdf * cos / pdf, ending after --max-bounces surfaces, on a miss (the environment, weighted
// against its cosine sample), or by Russian roulette from ReferencePush::rouletteStart on (kept
// with the chance of its throughput's largest channel, at most 0.95, and divided by it: unbiased).
// Every surface is shaded from both sides, as the ray-traced effects shade their hits.
#include "reference/path_lights.glsl"
#include "background/background.glsl"
#include "reference/reference_types.h"

layout(local_size_x = REFERENCE_GROUP_SIZE, local_size_y = REFERENCE_GROUP_SIZE) in;
layout(set = 0, binding = 1, rgba32f) uniform image2D gImagesRgba32f[];
layout(push_constant, scalar) uniform Push { ReferencePush p; } pc;

// One path through the pixel: the radiance it carries back to the camera.
vec3 tracePath(FrameConstants f, RtFrame rt, uvec2 pixel, bool alpha, inout bool covered,
               inout uint rays) {
    vec3 dir = viewRayAt(f, vec2(pixel) + pathRandom2());
    vec3 origin = f.cameraPosition;
    vec3 radiance = vec3(0.0), throughput = vec3(1.0);
    float lastPdf = 0.0; // the BRDF sample's density that left the last surface
    vec3 lastNormal = vec3(0.0);
    for (uint bounce = 0u;; ++bounce) {
        ++rays;
        PathHit hit = traceClosest(f, rt, origin, dir, alpha, gPathRandom);
        covered = covered || bounce == 0u && hit.hit;
        if (!hit.hit) {
            if (bounce == 0u) return f.backgroundEnvironment != 0u
                                         ? environmentBackground(f.environment, dir)
                                         : f.backgroundColor;
            // Also reachable by the last surface's cosine sample of the environment.
            float envPdf = max(dot(lastNormal, dir), 0.0) / PI;
            radiance += throughput * environmentRadiance(f.environment, dir) *
                        balanceWeight(lastPdf, envPdf);
            break;
        }
        RtHitSurface h = rtHitSurface(f, rt, hit.instance, hit.primitive, hit.bary, hit.frontFace);
        GpuMaterial mat = MaterialBuffer(f.materials).m[h.material];
        MaterialSample m = evaluateMaterial(mat, h.s);
        if (m.unlit) {
            radiance += throughput * m.baseColor;
            break;
        }
        PathVertex x;
        x.position = h.s.position;
        x.view = -dir;
        x.geometricNormal = dot(h.geometricNormal, dir) > 0.0 ? -h.geometricNormal : h.geometricNormal;
        x.normal = dot(m.normal, dir) > 0.0 ? -m.normal : m.normal; // the side the ray sees
        m = sheenForView(f.environment, m, x.normal, x.view);
        radiance += throughput * m.emissive;
        bool last = bounce >= pc.p.maxBounces;
        float specularChance = specularLobeChance(m, x.normal, x.view);
        radiance += throughput * directLights(f, rt, m, x, alpha, rays);
        radiance += throughput * directEnvironment(f, rt, m, x, specularChance, last, alpha, rays);
        if (last) break;
        if (bounce >= pc.p.rouletteStart) {
            float keep = min(max(throughput.r, max(throughput.g, throughput.b)), 0.95);
            if (pathRandom() >= keep) break;
            throughput /= keep;
        }
        vec3 u = vec3(pathRandom2(), pathRandom());
        vec3 next = sampleBrdf(m, x.normal, x.view, specularChance, u);
        float pdf = brdfSamplePdf(m, x.normal, x.view, next, specularChance);
        if (pdf <= 1e-8 || dot(x.geometricNormal, next) <= 0.0) break;
        vec3 weight = brdf(m, x.normal, x.view, next, vec3(1.0)) / pdf;
        if (all(equal(weight, vec3(0.0)))) break;
        throughput *= weight;
        lastPdf = pdf;
        lastNormal = x.normal;
        origin = pathRayOrigin(f, rt, x, next);
        dir = next;
    }
    return radiance;
}

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (pixel.x >= pc.p.width || pixel.y >= pc.p.height) return;
    FrameConstants f = FrameConstantsRef(pc.p.frame).f;
    RtFrame rt = RtFrameRef(f.rt).r;
    bool alpha = (pc.p.flags & REFERENCE_FLAG_ALPHA) != 0u;
    vec4 sum = vec4(0.0); // radiance, and the paths whose first ray met a surface
    uint rays = 0u;
    for (uint i = 0u; i < pc.p.samples; ++i) {
        pathRandomStart(pixel, pc.p.samplesBefore + i, pc.p.seed);
        bool covered = false;
        vec3 radiance = tracePath(f, rt, pixel, alpha, covered, rays);
        // (A path that went wrong numerically must not poison the mean.)
        if (any(isnan(radiance)) || any(isinf(radiance))) radiance = vec3(0.0);
        sum += vec4(radiance, covered ? 1.0 : 0.0);
    }
    rtCountRays(rt, rays);
    // The running mean (rgb: radiance, a: coverage) in float: every path weighs the same.
    vec4 mean = sum / float(pc.p.samples);
    if (pc.p.samplesBefore > 0u) {
        vec4 before = imageLoad(gImagesRgba32f[pc.p.accumulationSlot], ivec2(pixel));
        mean = before + (mean - before) * (float(pc.p.samples) /
                                           float(pc.p.samplesBefore + pc.p.samples));
    }
    imageStore(gImagesRgba32f[pc.p.accumulationSlot], ivec2(pixel), mean);
    imageStore(gImagesRgba16f[pc.p.hdrSlot], ivec2(pixel), mean);
}
