// --inspect X,Y: what the shading computed at one pixel, printed term by term through shaderPrintF
// and its kin. The terms are shadeSurface's (common/lighting.glsl) taken apart with the same
// functions (brdf, sunShadow, evaluateLight); PRINT_SHADED is shadeSurface's own result, and the
// GPU test checks that the printed terms add up to it, so the two cannot drift apart.
#ifndef SHADEL_INSPECT_GLSL
#define SHADEL_INSPECT_GLSL
#include "common/lighting.glsl"
#include "common/shader_print.glsl"

// The records of one fragment: its pixel and depth first (the CPU keeps the front fragment's).
void beginInspect(FrameConstants f, uint instance, uint triangle, vec4 fragCoord) {
    gPrintTag = ((instance * 0x9E3779B1u) ^ (triangle * 0x85EBCA6Bu) ^ 0x5Au) & 0xFFFFFFu;
    shaderPrintU4(f, PRINT_INSPECT_PIXEL, uvec4(uvec2(fragCoord.xy), 0u, 0u));
    shaderPrintF(f, PRINT_FRAGMENT_DEPTH, fragCoord.z);
}

void inspectSurface(FrameConstants f, uint instance, uint triangle, MaterialSample m,
                    vec3 worldPos, vec3 geometricNormal, vec3 shaded) {
    shaderPrintU(f, PRINT_INSTANCE, instance);
    shaderPrintU(f, PRINT_TRIANGLE, triangle);
    shaderPrintF3(f, PRINT_POSITION, worldPos);
    shaderPrintF3(f, PRINT_GEOMETRIC_NORMAL, geometricNormal);
    shaderPrintF3(f, PRINT_BASE_COLOR, m.baseColor);
    shaderPrintF(f, PRINT_ROUGHNESS, m.roughness);
    shaderPrintF(f, PRINT_METALLIC, m.metallic);
    shaderPrintF3(f, PRINT_SHADING_NORMAL, m.normal);
    shaderPrintF(f, PRINT_OCCLUSION, m.occlusion);
    shaderPrintF3(f, PRINT_EMISSIVE, m.emissive);

    vec3 n = m.normal;
    vec3 v = normalize(f.cameraPosition - worldPos);
    m = sheenForView(f.environment, m, n, v); // as shadeSurface does
    shaderPrintF3(f, PRINT_AMBIENT, environmentLight(f.environment, m, n, v,
                                                     m.occlusion * m.ambientOcclusion));
    if (dot(f.sunColor, f.sunColor) > 0.0) {
        float shadow = sunShadow(f, worldPos, geometricNormal);
        shaderPrintF(f, PRINT_SUN_SHADOW, shadow);
        shaderPrintF3(f, PRINT_SUN, brdf(m, n, v, -f.sunDirection, f.sunColor * shadow));
    }
    LightBuffer lights = LightBuffer(f.lights);
    for (uint i = 0u; i < min(f.lightCount, INSPECT_MAX_LIGHTS); ++i) {
        // evaluateLight: every kind as shadeSurface sums it (square spots, tubes, gobos, area
        // lights, clip planes), before blockers and spot shadows.
        vec3 term = evaluateLight(lights.l[i], m, n, v, worldPos);
        shaderPrintF4(f, PRINT_LIGHT, vec4(term, float(i)));
    }
    shaderPrintF3(f, PRINT_SHADED, shaded);
}
#endif
