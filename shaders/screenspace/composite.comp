#version 460
// Puts the screen-space results on the lit surfaces: skin takes most of its lighting from the
// scattered half-resolution image, and every surface adds what its reflection changes (the
// traced hit against the environment the shading already reflects) weighted by Fresnel
// (tiles without a smooth surface read the SSR target's cleared zeros). Sky pixels are the sky
// pass's.
#include "screenspace/sss.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

#define SSS_STRENGTH 0.75
#define DF_AO_STRENGTH 0.6 // the lit colour, not only its ambient part, is darkened (no split)

void main() {
    uvec2 tile = currentTile(pc.tiles, pc.listOffset);
    ivec2 p = ivec2(tile * TILE_SIZE + gl_LocalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) return;
    GBufferSample g = readGBuffer(p);
    if ((g.flags & PIXEL_SURFACE) == 0u) return;
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    vec4 color = imageLoad(gImagesRgba16f[pc.hdrSlot], p);
    if ((g.flags & PIXEL_SKIN) != 0u) {
        vec3 scattered = imageLoad(gImagesRgba16f[pc.sssSlot0], p / 2).rgb;
        color.rgb = mix(color.rgb, scattered, SSS_STRENGTH);
    }
    vec4 reflection = imageLoad(gImagesRgba16f[pc.ssrSlot], p);
    vec3 view = -viewDirectionAt(f, vec2(p) + 0.5);
    float f0 = (g.flags & PIXEL_WATER) != 0u ? 0.02 : 0.04;
    float fresnel = f0 + (1.0 - f0) * pow(1.0 - clamp(dot(g.normal, view), 0.0, 1.0), 5.0);
    // With the stencil-culled effects, the water composite (shaders/stencil) reflects the water.
    if (pc.stencilEffects == 0u || (g.flags & PIXEL_WATER) == 0u)
        color.rgb += reflection.rgb * reflection.a * fresnel;
    // Distance-field AO: the lighting applies it to the ambient (shaders/common/lighting.glsl)
    // when the frame's shading has the fields; else here, on the whole colour.
    if (pc.distanceFields != 0ul && f.distanceFields == 0ul)
        color.rgb *= mix(1.0, imageLoad(gImagesRgba8[pc.dfSlot], p).b, DF_AO_STRENGTH);
    imageStore(gImagesRgba16f[pc.hdrSlot], p, color);
}
