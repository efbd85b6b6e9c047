// Material evaluation shared by the forward and decoupled paths. Both pass explicit UV
// derivatives: the forward path from screen-space dFdx/dFdy, the decoupled path from the
// barycentrics of neighbouring shadels, so texture LOD selection is the same code.
#ifndef SHADEL_MATERIAL_GLSL
#define SHADEL_MATERIAL_GLSL
#include "common/bindless.glsl"
#include "streaming/feedback.glsl"

struct SurfaceInput {
    vec3 position;  // world
    vec3 normal;    // world, normalised geometric/interpolated normal
    vec4 tangent;   // world xyz + handedness
    vec2 uv;        // the first UV set (TEXCOORD_0)
    vec2 uvDx;      // derivatives of uv along the two screen (or shadel) axes
    vec2 uvDy;
    vec2 uv1;       // the second UV set (TEXCOORD_1) and its derivatives, for the texture slots
    vec2 uv1Dx;     // that read it (GpuMaterial.texCoords)
    vec2 uv1Dy;
    bool frontFacing;
};

struct MaterialSample {
    vec3 baseColor;
    float alpha;
    vec3 normal; // world, with normal map applied
    float metallic;
    float roughness;
    float occlusion;        // the material's occlusion texture: ambient and lights
    float ambientOcclusion; // AO decals (render/decals): ambient and indirect light only
    vec3 emissive;
    // glTF material extensions (defaults: plain metal/rough).
    vec3 specularF0;          // dielectric F0: ior and KHR_materials_specular (0.04 by default)
    float specularF90;        // dielectric F90 (1 by default)
    float clearcoat;          // coat weight, 0 = no coat
    float clearcoatRoughness; // perceptual
    vec3 clearcoatNormal;     // world
    vec3 sheenColor;          // 0 = no sheen
    float sheenRoughness;
    bool unlit;               // KHR_materials_unlit: the output is baseColor
    // What sheen leaves of the layers below toward the viewer: 1 - max(sheenColor) x the sheen's
    // directional albedo at n.v (the BRDF table's; set by sheenForView, else its mean 0.25).
    float sheenAlbedoScale;
};


#include "decals/decals.glsl"

// One-texel checker: texel x mod 2. It is a point function of the
// texel coordinate and has no filtered form, so any path that point-samples it aliases.
float texelChecker(vec2 uv, float scale) {
    ivec2 cell = ivec2(floor(uv * scale));
    return float((cell.x + cell.y) & 1);
}

vec3 bricks(vec2 uv, float scale) {
    vec2 p = uv * scale * vec2(1.0, 2.0);
    if ((int(floor(p.y)) & 1) == 1) p.x += 0.5;
    vec2 f = fract(p);
    float mortar = smoothstep(0.0, 0.06, f.x) * smoothstep(1.0, 0.94, f.x) *
                   smoothstep(0.0, 0.1, f.y) * smoothstep(1.0, 0.9, f.y);
    float tone = fract(sin(dot(floor(p), vec2(12.9898, 78.233))) * 43758.5453);
    vec3 brick = mix(vec3(0.55, 0.22, 0.15), vec3(0.7, 0.35, 0.25), tone);
    return mix(vec3(0.75, 0.72, 0.68), brick, mortar);
}

// Toksvig: a filtered normal (mip-mapped normal map, or the mean of several samples) shorter
// than 1 means the normals under the footprint disagree; widening the lobe by that variance keeps
// specular from aliasing. roughness is perceptual (alpha = roughness^2).
float toksvigRoughness(float roughness, float meanNormalLength) {
    // A unit normal stored in 8-bit texels reads up to about 0.007 short of 1 (a step of 1/255
    // in each component): encoding, not disagreement, and at 8 bits it would already roughen
    // a mirror to 0.25.
    float len = clamp(meanNormalLength + 0.007, 1e-3, 1.0);
    float alpha = roughness * roughness;
    return clamp(sqrt(sqrt(alpha * alpha + (1.0 - len) / len)), 0.0, 1.0);
}

// The bindless sampler of a material texture slot (GpuMaterial.samplers: its glTF sampler).
uint materialSampler(GpuMaterial m, uint slot) {
    return (m.samplers[slot >> 2u] >> ((slot & 3u) * 8u)) & 0xFFu;
}

// Whether a material texture slot reads the second UV set (TEXCOORD_1) instead of the first.
bool materialReadsUv1(GpuMaterial m, uint slot) {
    return ((m.texCoords >> slot) & 1u) != 0u;
}

// The UV set a texture slot reads, of the two a shader has at hand.
vec2 materialSlotUv(GpuMaterial m, uint slot, vec2 uv0, vec2 uv1) {
    return materialReadsUv1(m, slot) ? uv1 : uv0;
}

// A material texture through its slot's UV set and KHR_texture_transform (derivatives
// transformed with it) and its slot's sampler (wrap modes and filters as authored).
vec4 sampleMaterialTexture(GpuMaterial m, uint slot, uint tex, SurfaceInput s) {
    bool second = materialReadsUv1(m, slot);
    vec2 st = second ? s.uv1 : s.uv;
    vec2 stDx = second ? s.uv1Dx : s.uvDx;
    vec2 stDy = second ? s.uv1Dy : s.uvDy;
    vec2 c0 = m.uvTransform[slot * 3u], c1 = m.uvTransform[slot * 3u + 1u];
    vec2 uv = c0 * st.x + c1 * st.y + m.uvTransform[slot * 3u + 2u];
    vec2 dx = c0 * stDx.x + c1 * stDx.y;
    vec2 dy = c0 * stDy.x + c1 * stDy.y;
    uint samplerId = materialSampler(m, slot);
    // Filters without mipmaps read level 0 whatever the footprint: streaming must bring it in.
    bool level0 = (samplerId - SAMPLER_MATERIAL_FIRST) % SAMPLER_MIN_COUNT <= SAMPLER_MIN_LINEAR;
    recordTextureFeedback(tex, level0 ? vec2(0.0) : dx, level0 ? vec2(0.0) : dy);
    return sampleTexture(tex, samplerId, uv, dx, dy);
}

// The base colour's alpha where only coverage matters (alpha-tested depth and visibility
// passes, decoupled transparency): the same texture transform and sampler as shading. uv is the
// UV set the base colour reads (materialSlotUv with TEXTURE_SLOT_BASE_COLOR).
float materialBaseAlpha(GpuMaterial m, vec2 uv, vec2 uvDx, vec2 uvDy) {
    float alpha = m.baseColorFactor.a;
    if (m.baseColorTexture == NO_TEXTURE) return alpha;
    SurfaceInput s;
    s.uv = uv;
    s.uvDx = uvDx;
    s.uvDy = uvDy;
    s.uv1 = uv;
    s.uv1Dx = uvDx;
    s.uv1Dy = uvDy;
    return alpha * sampleMaterialTexture(m, TEXTURE_SLOT_BASE_COLOR, m.baseColorTexture, s).a;
}

// A tangent-space normal map applied to n; `roughness` widened by Toksvig (filtered normals
// are shorter).
vec3 applyNormalMap(GpuMaterial m, uint slot, uint tex, float scale, SurfaceInput s, vec3 n,
                    inout float roughness) {
    if (tex == NO_TEXTURE || dot(s.tangent.xyz, s.tangent.xyz) <= 1e-8) return n;
    vec3 t = normalize(s.tangent.xyz - n * dot(n, s.tangent.xyz));
    vec3 b = cross(n, t) * (s.tangent.w < 0.0 ? -1.0 : 1.0);
    vec3 tn = sampleMaterialTexture(m, slot, tex, s).xyz * 2.0 - 1.0;
    roughness = toksvigRoughness(roughness, length(tn));
    tn.xy *= scale;
    return normalize(t * tn.x + b * tn.y + n * max(tn.z, 1e-3));
}

// The material features this shader evaluates (MATERIAL_FEATURE_*): all of them, except in the
// shadel shading pipeline of plain materials (shaders/shadel/shade.comp), whose objects use
// none. On CPU devices a SIMD group runs the code of a branch none of its lanes takes, so each
// absent texture's sample still cost every shadel.
layout(constant_id = MATERIAL_FEATURES_CONSTANT_ID) const uint kMaterialFeatures = MATERIAL_FEATURES_ALL;
#define MATERIAL_HAS(feature) ((kMaterialFeatures & (feature)) != 0u)


MaterialSample evaluateMaterial(GpuMaterial m, SurfaceInput s) {
    MaterialSample o;
    vec4 base = m.baseColorFactor;
    if (m.baseColorTexture != NO_TEXTURE && MATERIAL_HAS(MATERIAL_FEATURE_TEXTURES))
        base *= sampleMaterialTexture(m, TEXTURE_SLOT_BASE_COLOR, m.baseColorTexture, s);
    if (MATERIAL_HAS(MATERIAL_FEATURE_PROCEDURAL) && m.procedural == PROCEDURAL_TEXEL_CHECKER)
        base.rgb *= mix(0.08, 1.0, texelChecker(s.uv, m.proceduralScale));
    else if (MATERIAL_HAS(MATERIAL_FEATURE_PROCEDURAL) && m.procedural == PROCEDURAL_BRICKS)
        base.rgb *= bricks(s.uv, m.proceduralScale);
    o.baseColor = base.rgb;
    o.alpha = base.a;

    o.metallic = m.metallicFactor;
    o.roughness = m.roughnessFactor;
    if (m.metallicRoughnessTexture != NO_TEXTURE && MATERIAL_HAS(MATERIAL_FEATURE_TEXTURES)) {
        vec4 mr = sampleMaterialTexture(m, TEXTURE_SLOT_METALLIC_ROUGHNESS, m.metallicRoughnessTexture, s);
        o.roughness *= mr.g;
        o.metallic *= mr.b;
    }
    o.roughness = clamp(o.roughness, 0.0, 1.0);
    o.metallic = clamp(o.metallic, 0.0, 1.0);

    o.occlusion = 1.0;
    if (m.occlusionTexture != NO_TEXTURE && MATERIAL_HAS(MATERIAL_FEATURE_TEXTURES)) {
        float ao = sampleMaterialTexture(m, TEXTURE_SLOT_OCCLUSION, m.occlusionTexture, s).r;
        o.occlusion = mix(1.0, ao, m.occlusionStrength);
    }

    o.emissive = m.emissiveFactor;
    if (m.emissiveTexture != NO_TEXTURE && MATERIAL_HAS(MATERIAL_FEATURE_TEXTURES))
        o.emissive *= sampleMaterialTexture(m, TEXTURE_SLOT_EMISSIVE, m.emissiveTexture, s).rgb;

    vec3 n = normalize(s.normal);
    if ((m.flags & MATERIAL_DOUBLE_SIDED) != 0u && !s.frontFacing) n = -n;
    o.normal = n;
    if (MATERIAL_HAS(MATERIAL_FEATURE_TEXTURES))
        o.normal = applyNormalMap(m, TEXTURE_SLOT_NORMAL, m.normalTexture, m.normalScale, s, n, o.roughness);

    // KHR_materials_specular: strength in the specular texture's A, the F0 tint in the colour
    // texture's RGB (sRGB), both multiplying their factors.
    float specularStrength = 1.0;
    vec3 specularTint = m.specularColorFactor;
    if (m.specularTexture != NO_TEXTURE && MATERIAL_HAS(MATERIAL_FEATURE_TEXTURES))
        specularStrength = sampleMaterialTexture(m, TEXTURE_SLOT_SPECULAR, m.specularTexture, s).a;
    if (m.specularColorTexture != NO_TEXTURE && MATERIAL_HAS(MATERIAL_FEATURE_TEXTURES))
        specularTint *= sampleMaterialTexture(m, TEXTURE_SLOT_SPECULAR_COLOR, m.specularColorTexture, s).rgb;
    o.specularF0 = min(m.dielectricF0Scalar * specularTint, vec3(1.0)) * specularStrength;
    o.specularF90 = m.specularFactor * specularStrength;
    o.clearcoat = MATERIAL_HAS(MATERIAL_FEATURE_CLEARCOAT) ? m.clearcoatFactor : 0.0;
    o.clearcoatRoughness = m.clearcoatRoughnessFactor;
    o.clearcoatNormal = n; // the coat follows the geometry, not the base layer's normal map
    if (o.clearcoat > 0.0) {
        if (m.clearcoatTexture != NO_TEXTURE && MATERIAL_HAS(MATERIAL_FEATURE_TEXTURES))
            o.clearcoat *= sampleMaterialTexture(m, TEXTURE_SLOT_CLEARCOAT, m.clearcoatTexture, s).r;
        if (m.clearcoatRoughnessTexture != NO_TEXTURE && MATERIAL_HAS(MATERIAL_FEATURE_TEXTURES))
            o.clearcoatRoughness *= sampleMaterialTexture(m, TEXTURE_SLOT_CLEARCOAT_ROUGHNESS,
                                                          m.clearcoatRoughnessTexture, s).g;
        o.clearcoatRoughness = clamp(o.clearcoatRoughness, 0.0, 1.0);
        o.clearcoatNormal = applyNormalMap(m, TEXTURE_SLOT_CLEARCOAT_NORMAL, m.clearcoatNormalTexture,
                                           m.clearcoatNormalScale, s, n, o.clearcoatRoughness);
    }
    // KHR_materials_sheen: colour in the colour texture's RGB (sRGB), roughness in the
    // roughness texture's A, both multiplying their factors.
    o.sheenColor = MATERIAL_HAS(MATERIAL_FEATURE_SHEEN) ? m.sheenColorFactor : vec3(0.0);
    float sheenRoughness = m.sheenRoughnessFactor;
    if (any(greaterThan(o.sheenColor, vec3(0.0)))) {
        if (m.sheenColorTexture != NO_TEXTURE && MATERIAL_HAS(MATERIAL_FEATURE_TEXTURES))
            o.sheenColor *= sampleMaterialTexture(m, TEXTURE_SLOT_SHEEN_COLOR, m.sheenColorTexture, s).rgb;
        if (m.sheenRoughnessTexture != NO_TEXTURE && MATERIAL_HAS(MATERIAL_FEATURE_TEXTURES))
            sheenRoughness *= sampleMaterialTexture(m, TEXTURE_SLOT_SHEEN_ROUGHNESS,
                                                    m.sheenRoughnessTexture, s).a;
    }
    o.sheenRoughness = max(sheenRoughness, 0.07);
    o.sheenAlbedoScale = 1.0 - max(o.sheenColor.r, max(o.sheenColor.g, o.sheenColor.b)) * 0.25;
    o.unlit = (m.flags & MATERIAL_UNLIT) != 0u;
    o.ambientOcclusion = 1.0;
    applyDecals(o, s.position, n); // the caller's decal list, if it chose one (decals.glsl)
    return o;
}
#endif
