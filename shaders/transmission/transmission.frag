#version 460
// Transmissive surfaces (KHR_materials_transmission, KHR_materials_volume), drawn after the
// opaque scene over a mipmapped copy of it (render/transmission): the shared material and
// lighting code with the transmitted lobes compiled in (common/transmission.glsl). The copy is
// read where the refracted ray leaves the volume, at the MIP the transmitted lobe's roughness
// spreads over.
#define SHADEL_TRANSMISSION_LOBE 1
#include "common/lighting.glsl"

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint shadowView;       // (forward.vert's; unused)
    uint backgroundSlot;   // the scene colour's mipmapped copy (bindless)
    uint backgroundLevels; // its MIP count
} pc;

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inTangent;
layout(location = 3) in vec2 inUv;
layout(location = 4) flat in uint inInstance;
layout(location = 7) in vec2 inUv1; // the second UV set

layout(location = 0) out vec4 outColor;

// Clamped at the edges, trilinear.
const uint kBackgroundSampler =
    SAMPLER_MATERIAL_FIRST +
    ((SAMPLER_WRAP_CLAMP_TO_EDGE * 3u + SAMPLER_WRAP_CLAMP_TO_EDGE) * 2u + SAMPLER_MAG_LINEAR) *
        SAMPLER_MIN_COUNT +
    SAMPLER_MIN_LINEAR_MIPMAP_LINEAR;

// The opaque scene's light where `exit` projects, blurred over the footprint of a lobe of
// perceptual roughness `rough`: a fully rough one averages the whole view (the top MIP), and
// each tenth less halves the footprint, whatever the target's size.
vec3 backgroundAt(FrameConstants f, vec3 exit, float rough) {
    vec4 clip = f.viewProj * vec4(exit, 1.0);
    vec2 uv = clip.xy / max(clip.w, 1e-6) * 0.5 + 0.5;
    float top = float(pc.backgroundLevels - 1u);
    float lod = clamp(top - 10.0 * (1.0 - rough), 0.0, top);
    return sampleTextureLod(pc.backgroundSlot, kBackgroundSampler, uv, lod).rgb;
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    GpuInstance inst = InstanceBuffer(f.instances).i[inInstance];
    GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
    gTextureFeedback = f.textureFeedback;
    SurfaceInput s;
    s.position = inPosition;
    s.normal = normalize(inNormal);
    s.tangent = inTangent;
    s.uv = inUv;
    s.uvDx = dFdx(inUv);
    s.uvDy = dFdy(inUv);
    s.uv1 = inUv1;
    s.uv1Dx = dFdx(inUv1);
    s.uv1Dy = dFdy(inUv1);
    s.frontFacing = gl_FrontFacing;
    MaterialSample m = evaluateMaterial(mat, s);
    if ((mat.flags & MATERIAL_ALPHA_MASK) != 0u && m.alpha < mat.alphaCutoff) discard;

    float factor = mat.transmissionFactor;
    if (mat.transmissionTexture != NO_TEXTURE)
        factor *= sampleMaterialTexture(mat, TEXTURE_SLOT_TRANSMISSION, mat.transmissionTexture, s).r;
    float thickness = mat.thicknessFactor;
    if (mat.thicknessTexture != NO_TEXTURE)
        thickness *= sampleMaterialTexture(mat, TEXTURE_SLOT_THICKNESS, mat.thicknessTexture, s).g;
    vec3 v = normalize(f.cameraPosition - inPosition);
    gTransmission.factor = factor;
    gTransmission.ior = mat.ior;
    gTransmission.ray = volumeTransmissionRay(m.normal, v, thickness, mat.ior, inst.model);
    gTransmission.attenuation = volumeTransmittance(mat.attenuationColor, mat.attenuationDistance,
                                                    length(gTransmission.ray));
    gTransmission.background =
        backgroundAt(f, inPosition + gTransmission.ray, transmissionRoughness(m.roughness, mat.ior)) *
        gTransmission.attenuation;

    vec3 color = shadeSurface(f, m, inPosition, s.normal);
    outColor = vec4(color, 1.0);
}
