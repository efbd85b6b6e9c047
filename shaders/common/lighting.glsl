// Lighting shared by the forward and decoupled paths: GGX specular + Lambert diffuse, the
// sun with a PCF shadow map, point and spot lights with glTF's range falloff.
#ifndef SHADEL_LIGHTING_GLSL
#define SHADEL_LIGHTING_GLSL
#include "common/material.glsl"

const float PI = 3.14159265358979;

float distributionGgx(float nh, float a2) {
    float d = nh * nh * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

float visibilitySmithGgx(float nv, float nl, float a2) {
    float gv = nl * sqrt(nv * nv * (1.0 - a2) + a2);
    float gl = nv * sqrt(nl * nl * (1.0 - a2) + a2);
    return 0.5 / max(gv + gl, 1e-5);
}

vec3 fresnelSchlick(vec3 f0, float vh) {
    return f0 + (1.0 - f0) * pow(1.0 - vh, 5.0);
}

// KHR_materials_sheen: Charlie distribution and Neubelt's visibility (Estevez and Kulla 2017).
float distributionCharlie(float nh, float alpha) {
    float inv = 1.0 / alpha;
    float sin2 = max(1.0 - nh * nh, 0.0078125);
    return (2.0 + inv) * pow(sin2, inv * 0.5) / (2.0 * PI);
}

// Radiance reflected toward v from a light of `radiance` arriving from direction l: the base
// layer (GGX + Lambert, dielectric F0/F90 from ior and specular), under sheen (its albedo taken
// from the layer below by max(sheen colour)), under the clear coat (Fresnel 0.04 on its own
// normal; what it reflects does not reach the layers below).
vec3 brdf(MaterialSample m, vec3 n, vec3 v, vec3 l, vec3 radiance) {
    float nl = dot(n, l);
    float coatNl = m.clearcoat > 0.0 ? dot(m.clearcoatNormal, l) : 0.0;
    if (nl <= 0.0 && coatNl <= 0.0) return vec3(0.0);
    vec3 h = normalize(v + l);
    float vh = max(dot(v, h), 0.0);
    vec3 color = vec3(0.0);
    if (nl > 0.0) {
        float nv = max(dot(n, v), 1e-4);
        float nh = max(dot(n, h), 0.0);
        float a = m.roughness * m.roughness;
        float a2 = a * a;
        vec3 f0 = mix(m.specularF0, m.baseColor, m.metallic);
        float f90 = mix(m.specularF90, 1.0, m.metallic);
        vec3 f = f0 + (f90 - f0) * pow(1.0 - vh, 5.0);
        vec3 specular = f * distributionGgx(nh, a2) * visibilitySmithGgx(nv, nl, a2);
        vec3 diffuse = (1.0 - f) * (1.0 - m.metallic) * m.baseColor / PI;
        color = diffuse + specular;
        float sheenMax = max(m.sheenColor.r, max(m.sheenColor.g, m.sheenColor.b));
        if (sheenMax > 0.0) {
            float alpha = m.sheenRoughness * m.sheenRoughness;
            vec3 sheen = m.sheenColor * distributionCharlie(nh, alpha) /
                         (4.0 * (nl + nv - nl * nv));
            color = color * (1.0 - sheenMax * 0.25) + sheen;
        }
        color *= nl;
    }
    if (m.clearcoat > 0.0) {
        vec3 cn = m.clearcoatNormal;
        float cnv = max(dot(cn, v), 1e-4);
        float fcView = 0.04 + 0.96 * pow(1.0 - cnv, 5.0);
        color *= 1.0 - m.clearcoat * fcView;
        if (coatNl > 0.0) {
            float ca = m.clearcoatRoughness * m.clearcoatRoughness;
            float ca2 = ca * ca;
            float fc = 0.04 + 0.96 * pow(1.0 - vh, 5.0);
            color += m.clearcoat * fc * distributionGgx(max(dot(cn, h), 0.0), ca2) *
                     visibilitySmithGgx(cnv, coatNl, ca2) * coatNl;
        }
    }
    return color * radiance;
}

// 3x3 PCF on the sun's shadow map (reversed-Z is not used for the orthographic shadow map).
float sunShadow(FrameConstants f, vec3 worldPos, vec3 n) {
    if (f.sunShadowSlot == NO_TEXTURE) return 1.0;
    // Normal offset scaled by the texel size keeps acne away on grazing surfaces.
    vec3 p = worldPos + n * f.shadowTexelSize * 1.5;
    vec4 clip = f.sunViewProj * vec4(p, 1.0);
    vec3 ndc = clip.xyz / clip.w;
    vec2 uv = ndc.xy * 0.5 + 0.5;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || ndc.z > 1.0) return 1.0;
    float depth = ndc.z - 0.0015;
    vec2 texel = 1.0 / vec2(textureSize(gTextures[f.sunShadowSlot], 0));
    float lit = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x)
            lit += texture(sampler2DShadow(gTextures[f.sunShadowSlot], gShadowSamplers[SAMPLER_SHADOW]),
                           vec3(uv + vec2(x, y) * texel, depth));
    return lit / 9.0;
}

float rangeAttenuation(float distance, float range) {
    float invSquare = 1.0 / max(distance * distance, 1e-4);
    if (range <= 0.0) return invSquare;
    float r = distance / range;
    float window = clamp(1.0 - r * r * r * r, 0.0, 1.0);
    return invSquare * window * window;
}

// Everything that lights a surface point, evaluated for a viewer at f.cameraPosition.
vec3 shadeSurface(FrameConstants f, MaterialSample m, vec3 worldPos, vec3 geometricNormal) {
    if (m.unlit) return m.baseColor;
    vec3 n = m.normal;
    vec3 v = normalize(f.cameraPosition - worldPos);
    vec3 color = m.emissive;
    // Ambient: a hemisphere term so shadowed sides are not black.
    float up = n.y * 0.5 + 0.5;
    vec3 ambient = mix(f.ambientColor * 0.5, f.ambientColor + f.skyColor * 0.15, up);
    vec3 ambientLit = ambient * m.baseColor * (1.0 - m.metallic * 0.5) * m.occlusion;
    if (m.clearcoat > 0.0) {
        // The coat mirrors the same hemisphere (sky above, ground below) by its Fresnel; what it
        // reflects does not reach the base.
        float fc = m.clearcoat * (0.04 + 0.96 * pow(1.0 - max(dot(m.clearcoatNormal, v), 0.0), 5.0));
        vec3 r = reflect(-v, m.clearcoatNormal);
        vec3 mirrored = mix(f.ambientColor * 0.5, f.ambientColor + f.skyColor, r.y * 0.5 + 0.5);
        ambientLit = ambientLit * (1.0 - fc) + fc * mirrored * m.occlusion;
    }
    color += ambientLit;

    vec3 l = -f.sunDirection;
    if (dot(f.sunColor, f.sunColor) > 0.0)
        color += brdf(m, n, v, l, f.sunColor * sunShadow(f, worldPos, geometricNormal));

    LightBuffer lights = LightBuffer(f.lights);
    for (uint i = 0u; i < f.lightCount; ++i) {
        GpuLight light = lights.l[i];
        vec3 radiance = light.color;
        vec3 dir;
        if (light.type == LIGHT_DIRECTIONAL) {
            dir = -light.direction;
        } else {
            vec3 toLight = light.position - worldPos;
            float dist = length(toLight);
            dir = toLight / max(dist, 1e-4);
            radiance *= rangeAttenuation(dist, light.range);
            if (light.type == LIGHT_SPOT) {
                float cd = dot(light.direction, -dir);
                float s = clamp(cd * light.spotScale + light.spotOffset, 0.0, 1.0);
                radiance *= s * s;
            }
        }
        color += brdf(m, n, v, dir, radiance) * m.occlusion;
    }
    return color;
}
#endif
