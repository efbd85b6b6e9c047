// Image-based lighting of a surface point: the environment's irradiance and prefiltered
// specular through the split-sum BRDF table, with the glTF BRDF's dielectric/metal mix, sheen and
// clear coat as the lights have them (common/lighting.glsl brdf), so the lights and the
// environment agree on every material. Included by lighting.glsl after brdf's helpers.
#ifndef SHADEL_ENVIRONMENT_LIGHTING_GLSL
#define SHADEL_ENVIRONMENT_LIGHTING_GLSL
#include "environment/environment.glsl"

// The directional albedo of a specular layer with Fresnel F0..F90 at (n.v, roughness), from the
// table's scale and bias (`ab`): single scattering with the roughness-dependent Fresnel of
// Fdez-Aguera's split sum, plus the energy multiple scattering between microfacets adds back
// (which single-scattering GGX loses on rough surfaces: rough metals would be too dark).
vec3 specularAlbedo(vec3 f0, float f90, float nv, float roughness, vec2 ab) {
    vec3 fr = max(vec3(1.0 - roughness), f0) - f0;
    vec3 single = (f0 + fr * pow(1.0 - nv, 5.0)) * ab.x + f90 * ab.y;
    float missing = 1.0 - (ab.x + ab.y);
    vec3 fAverage = f90 * (f0 + (1.0 - f0) / 21.0);
    return single + missing * single * fAverage / (1.0 - fAverage * missing);
}

// Specular occlusion from an ambient occlusion value (Lagarde and de Rousiers): the visible
// cone of directions narrows the specular lobe's share less at normal incidence and for sharp
// lobes, more at grazing angles and for wide ones.
float specularOcclusion(float nv, float occlusion, float roughness) {
    float alpha = roughness * roughness;
    return clamp(pow(nv + occlusion, exp2(-16.0 * alpha - 1.0)) - 1.0 + occlusion, 0.0, 1.0);
}

// The sheen's albedo scaling for the view direction (KHR_materials_sheen): the layers below
// keep 1 - max(sheenColor) x E(n.v), E the sheen's directional albedo from the BRDF table. Used
// for the lights too: E(n.l), which the extension's min() also asks for, matters only where
// n.l (and so the light's share) is small.
MaterialSample sheenForView(GpuEnvironment e, MaterialSample m, vec3 n, vec3 v) {
    float sheenMax = max(m.sheenColor.r, max(m.sheenColor.g, m.sheenColor.b));
    if (MATERIAL_HAS(MATERIAL_FEATURE_SHEEN) && sheenMax > 0.0 && e.brdfSize > 0.0) {
        float nv = clamp(dot(n, v), 1e-4, 1.0);
        m.sheenAlbedoScale = 1.0 - sheenMax * min(environmentBrdf(e, nv, m.sheenRoughness).z, 1.0);
    }
    return m;
}

// The environment's light reflected toward v; `occlusion` darkens it (the material's occlusion
// map, AO decals, ray-traced or distance-field AO).
vec3 environmentLight(GpuEnvironment e, MaterialSample m, vec3 n, vec3 v, float occlusion) {
    // (A transmissive surface shows what lies behind it with or without an environment.)
    if ((e.flags & ENVIRONMENT_FLAG_NONE) != 0u && !transmissionLobe()) return vec3(0.0);
    float nv = clamp(dot(n, v), 1e-4, 1.0);
    vec3 table = environmentBrdf(e, nv, m.roughness);
    vec3 specularLight = environmentSpecular(e, reflect(-v, n), m.roughness) *
                         specularOcclusion(nv, occlusion, m.roughness);
    vec3 diffuseLight = environmentIrradiance(e, n) * m.baseColor * occlusion;
    if (transmissionLobe()) // KHR_materials_transmission (common/transmission.glsl)
        diffuseLight = mix(diffuseLight, transmittedBackground(m, table.xy), gTransmission.factor);
    vec3 dielectricF = specularAlbedo(m.specularF0, m.specularF90, nv, m.roughness, table.xy);
    vec3 metalF = specularAlbedo(m.baseColor, 1.0, nv, m.roughness, table.xy);
    vec3 dielectric = diffuseLight * (1.0 - dielectricF) + specularLight * dielectricF;
    vec3 color = mix(dielectric, specularLight * metalF, m.metallic);
    float sheenMax = max(m.sheenColor.r, max(m.sheenColor.g, m.sheenColor.b));
    if (MATERIAL_HAS(MATERIAL_FEATURE_SHEEN) && sheenMax > 0.0) {
        // (The Charlie lobe with its visibility term is not energy conserving at grazing views
        // of smooth sheen: its albedo passes 1 there, and the layer below would go negative.)
        float sheenAlbedo = min(environmentBrdf(e, nv, m.sheenRoughness).z, 1.0);
        vec3 sheenLight = environmentSheen(e, reflect(-v, n), m.sheenRoughness) * occlusion;
        color = color * (1.0 - sheenMax * sheenAlbedo) + sheenLight * m.sheenColor * sheenAlbedo;
    }
    if (MATERIAL_HAS(MATERIAL_FEATURE_CLEARCOAT) && m.clearcoat > 0.0) {
        vec3 cn = m.clearcoatNormal;
        float cnv = clamp(dot(cn, v), 1e-4, 1.0);
        vec3 coatLight = environmentSpecular(e, reflect(-v, cn), m.clearcoatRoughness) *
                         specularOcclusion(cnv, occlusion, m.clearcoatRoughness);
        color = mix(color, coatLight, clearcoatFresnel(m, v));
    }
    return color;
}
#endif
