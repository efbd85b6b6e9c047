#version 460
// The water composite (water stenciling): screen-space reflection and a refraction
// tint on the water's pixels. A full-screen triangle: with the stencil test (EQUAL to
// STENCIL_WATER) only water pixels run it; the full-screen version (bench, tests) runs every
// pixel and branches on the G-buffer class. Early fragment tests: the shader stores to the scene
// colour, and without them lavapipe would shade every pixel before testing the stencil.
#define SCREEN_SPACE_FRAGMENT // no tile lists here
#include "screenspace/screen_space.glsl"
#include "environment/environment.glsl"

layout(early_fragment_tests) in;

#define WATER_F0 0.02
// Light crossing the water body loses red first; grazing views cross more of it.
const vec3 kRefractionTint = vec3(0.55, 0.82, 0.88);

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    GBufferSample g = readGBuffer(p);
    if ((g.flags & PIXEL_WATER) == 0u) return; // only the full-screen version gets here
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    vec4 color = imageLoad(gImagesRgba16f[pc.hdrSlot], p);
    vec4 reflection = imageLoad(gImagesRgba16f[pc.ssrSlot], p);
    vec3 view = -viewDirectionAt(f, vec2(p) + 0.5);
    float cosView = clamp(dot(g.normal, view), 0.0, 1.0);
    float fresnel = WATER_F0 + (1.0 - WATER_F0) * pow(1.0 - cosView, 5.0);
    vec3 refracted = color.rgb * mix(kRefractionTint, vec3(1.0), cosView);
    // The SSR target holds what a traced hit changes against the environment's reflection.
    vec3 reflected = environmentSpecular(f.environment, reflect(-view, g.normal), g.roughness) +
                     reflection.rgb * reflection.a;
    color.rgb = refracted * (1.0 - fresnel) + reflected * fresnel;
    imageStore(gImagesRgba16f[pc.hdrSlot], p, color);
}
