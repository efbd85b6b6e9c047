// Sampling the shared BRDF (common/lighting.glsl brdf, which the reference only evaluates): a
// one-sample mixture of cosine-weighted directions (the Lambert lobe) and GGX visible normals
// (Heitz 2018, the specular lobe at the same alpha the BRDF uses, lightLobeAlpha), chosen by
// the lobes' Fresnel-weighted albedos at the view. The mixture's density covers every direction
// above the shading normal, so brdf / pdf is unbiased whatever lobe was drawn.
#ifndef SHADEL_PATH_SAMPLING_GLSL
#define SHADEL_PATH_SAMPLING_GLSL
#include "raytracing/rt_effects.glsl" // rtBasis, rtCosineDirection, PI, brdf

float pathLuminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

// The probability of drawing the specular lobe (0 for a view below the shading normal, which
// visible normals cannot take).
float specularLobeChance(MaterialSample m, vec3 n, vec3 v) {
    float nv = dot(n, v);
    if (nv <= 1e-4) return 0.0;
    vec3 diffuseWeight, specularWeight;
    gltfFresnelWeights(m, nv, diffuseWeight, specularWeight);
    float specular = pathLuminance(specularWeight);
    float diffuse = pathLuminance(diffuseWeight * m.baseColor);
    if (specular + diffuse <= 0.0) return 0.5;
    return clamp(specular / (specular + diffuse), 0.0, 1.0);
}

float smithG1(float nv, float a2) { return 2.0 * nv / (nv + sqrt(a2 + (1.0 - a2) * nv * nv)); }

// A visible normal of the GGX distribution of `alpha` for the view v (local frame, z = normal).
vec3 sampleGgxVisibleNormal(vec3 v, float alpha, vec2 u) {
    vec3 vh = normalize(vec3(alpha * v.x, alpha * v.y, v.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = lensq > 0.0 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(lensq) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(vh, t1);
    float r = sqrt(u.x);
    float phi = 2.0 * PI * u.y;
    float p1 = r * cos(phi);
    float p2 = r * sin(phi);
    float s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2;
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3(alpha * nh.x, alpha * nh.y, max(0.0, nh.z)));
}

// Density (solid angle) of l under the mixture.
float brdfSamplePdf(MaterialSample m, vec3 n, vec3 v, vec3 l, float specularChance) {
    float nl = dot(n, l);
    if (nl <= 0.0) return 0.0;
    float diffusePdf = nl / PI;
    float nv = max(dot(n, v), 1e-4);
    vec3 h = normalize(v + l);
    float a = lightLobeAlpha(m.roughness);
    float a2 = a * a;
    float specularPdf = distributionGgx(max(dot(n, h), 0.0), a2) * smithG1(nv, a2) / (4.0 * nv);
    return mix(diffusePdf, specularPdf, specularChance);
}

// A direction drawn from the mixture (may point below the surface: the caller ends the path).
vec3 sampleBrdf(MaterialSample m, vec3 n, vec3 v, float specularChance, vec3 u) {
    if (u.z >= specularChance) return rtCosineDirection(n, u.xy);
    mat3 basis = rtBasis(n);
    vec3 localV = transpose(basis) * v;
    vec3 h = basis * sampleGgxVisibleNormal(localV, lightLobeAlpha(m.roughness), u.xy);
    return reflect(-v, h);
}

// The balance heuristic of one sample of density `a` against one of density `b`.
float balanceWeight(float a, float b) { return a + b > 0.0 ? a / (a + b) : 0.0; }
#endif
