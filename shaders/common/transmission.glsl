// KHR_materials_transmission and KHR_materials_volume, shared by every path that shades a
// transmissive surface (render/transmission): the surface transmits, in place of the share
// transmissionFactor of its diffuse lobe, the light behind it through a microfacet BTDF whose
// lobe is the reflection's mirrored through the surface, its width scaled by the IOR. Behind a
// volume the light comes from where the refracted ray leaves it (thickness x the instance's
// scale along refract(-v, n, 1 / ior)) and is attenuated along that length (Beer-Lambert:
// attenuationColor after attenuationDistance). Included by lighting.glsl: brdf() adds the
// lights' transmitted lobe and environmentLight() the transmitted background, both only where
// SHADEL_TRANSMISSION_LOBE is defined to 1 before the include (the transmission pass). Needs
// lighting.glsl's GGX terms and dielectricFresnel.
#ifndef SHADEL_TRANSMISSION_GLSL
#define SHADEL_TRANSMISSION_GLSL

#ifndef SHADEL_TRANSMISSION_LOBE
#define SHADEL_TRANSMISSION_LOBE 0
#endif

struct TransmissionSample {
    float factor;     // 0: no transmission (the other fields are unused)
    float ior;
    vec3 ray;         // through the volume, world space; 0 for a thin-walled surface
    vec3 background;  // the light arriving along the ray's exit, attenuated in the volume
    vec3 attenuation; // the volume's transmittance along the ray (1 when thin)
};
// Set by the shading pass before shadeSurface; factor 0 leaves every lobe opaque.
TransmissionSample gTransmission = TransmissionSample(0.0, 1.5, vec3(0.0), vec3(0.0), vec3(1.0));

bool transmissionLobe() {
    return SHADEL_TRANSMISSION_LOBE != 0 && gTransmission.factor > 0.0;
}

// The transmitted lobe's perceptual roughness: the refraction spreads a rough lobe less the
// closer the IOR is to 1 (none at 1, as much as the reflection's from 1.5 up).
float transmissionRoughness(float perceptualRoughness, float ior) {
    return perceptualRoughness * clamp(2.0 * ior - 2.0, 0.0, 1.0);
}

// Beer-Lambert: the share of light left after `distance` in a medium that leaves `color` of it
// after `attenuationDistance` (infinite: a clear medium).
vec3 volumeTransmittance(vec3 color, float attenuationDistance, float distance) {
    if (isinf(attenuationDistance) || attenuationDistance <= 0.0 || distance <= 0.0)
        return vec3(1.0);
    return pow(max(color, vec3(0.0)), vec3(distance / attenuationDistance));
}

// The refracted ray through the volume: its direction entering at normal n seen from v, its
// length the thickness scaled by the instance's transform (the thickness is in mesh space).
vec3 volumeTransmissionRay(vec3 n, vec3 v, float thickness, float ior, mat4 model) {
    vec3 dir = refract(-v, n, 1.0 / max(ior, 1.0));
    if (dot(dir, dir) < 1e-12) dir = -v;
    vec3 scale = vec3(length(model[0].xyz), length(model[1].xyz), length(model[2].xyz));
    return normalize(dir) * thickness * scale;
}

// The lights' transmitted lobe for light arriving from l (behind the surface for a thin one):
// GGX with l mirrored through the surface plane, times (1 - F) and the base colour, along the
// volume's transmittance. Radiance per unit light radiance, without a cosine (the microfacet
// BTDF of the extension's reference model).
vec3 transmissionBtdf(MaterialSample m, vec3 n, vec3 v, vec3 l) {
    vec3 mirrored = reflect(l, n); // through the surface plane
    vec3 h = normalize(mirrored + v);
    // The lights' floor of perceptual roughness (lightLobeAlpha's 0.04) keeps the lobe finite at IOR 1.
    float a = max(transmissionRoughness(m.roughness, gTransmission.ior), 0.04);
    a *= a;
    float a2 = a * a;
    float nl = clamp(dot(n, mirrored), 0.0, 1.0), nv = clamp(dot(n, v), 1e-4, 1.0);
    float lobe = distributionGgx(clamp(dot(n, h), 0.0, 1.0), a2) * visibilitySmithGgx(nv, nl, a2);
    vec3 f = dielectricFresnel(m, clamp(dot(v, h), 0.0, 1.0));
    return (1.0 - f) * m.baseColor * lobe * gTransmission.attenuation;
}

// The environment's share: the background behind the surface through the base colour, less
// what the specular layer reflects (its split-sum albedo F0 * ab.x + F90 * ab.y).
vec3 transmittedBackground(MaterialSample m, vec2 ab) {
    vec3 reflected = m.specularF0 * ab.x + m.specularF90 * ab.y;
    return (1.0 - reflected) * m.baseColor * gTransmission.background;
}
#endif
