#version 460
// Reflective shadow map texel: world position, normal (+ the surface area it stands for) and
// the flux the surface reflects diffusely (a virtual point light for the LPV injection).
#include "common/lighting.glsl"
#include "gi/rsm_push.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inTangent;
layout(location = 3) in vec2 inUv;
layout(location = 7) in vec2 inUv1; // the second UV set (TEXCOORD_1)
layout(location = 4) flat in uint inInstance;

layout(location = 0) out vec4 outPosition; // xyz world, w = 1 where a surface was drawn
layout(location = 1) out vec4 outNormal;   // xyz normal (facing the light), w = surface area
layout(location = 2) out vec4 outFlux;     // rgb flux reflected diffusely

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    GpuInstance inst = InstanceBuffer(f.instances).i[inInstance];
    GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
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
    // Drawn without culling and one front face for every instance: a mirroring transform turns
    // the rasterizer's facing around.
    s.frontFacing = gl_FrontFacing != (determinant(mat3(inst.model)) < 0.0);
    MaterialSample m = evaluateMaterial(mat, s);
    if ((mat.flags & MATERIAL_ALPHA_MASK) != 0u && m.alpha < mat.alphaCutoff) discard;

    vec3 toLight;
    vec3 flux;               // irradiance perpendicular to the light x the texel's area there
    float areaPerpendicular; // the texel's area perpendicular to the light, at the surface
    if (pc.light == 0xFFFFFFFFu) {
        toLight = -f.sunDirection;
        areaPerpendicular = pc.texelArea;
        flux = f.sunColor * pc.texelArea;
    } else {
        GpuLight light = LightBuffer(f.lights).l[pc.light];
        vec3 d = light.position - inPosition;
        float dist = length(d);
        toLight = d / max(dist, 1e-4);
        float cd = dot(light.direction, -toLight);
        float spot = clamp(cd * light.spotScale + light.spotOffset, 0.0, 1.0);
        // A texel's solid angle falls with cos^3 of its angle off the axis.
        float solidAngle = pc.texelSolidAngle * cd * cd * cd;
        areaPerpendicular = solidAngle * dist * dist;
        // Intensity x solid angle: the flux through the texel, with the shading's falloff.
        flux = light.color * spot * spot * rangeAttenuation(dist, light.range) * dist * dist *
               solidAngle;
    }
    vec3 n = m.normal;
    if (dot(n, toLight) < 0.0) n = -n; // the lit side reflects
    float cosTheta = max(dot(n, toLight), 0.05);
    outPosition = vec4(inPosition, 1.0);
    outNormal = vec4(n, areaPerpendicular / cosTheta);
    // Diffuse reflection only (metals reflect specularly; the LPV carries diffuse light).
    outFlux = vec4(flux * m.baseColor * (1.0 - m.metallic), 1.0);
}
