// Shared by the screen-space passes: push constants, the thin G-buffer's decoding, depth to
// position, the sky (also what reflections that leave the screen see).
#ifndef SHADEL_SCREEN_SPACE_GLSL
#define SHADEL_SCREEN_SPACE_GLSL
#include "common/bindless.glsl"
#include "screenspace/screen_space_types.h"
#include "tiles/tile_list.glsl"

layout(push_constant, scalar) uniform Push {
    ScreenSpacePush pc;
};

struct GBufferSample {
    vec3 normal; // world space, unit
    float roughness;
    uint flags; // PIXEL_* bits
    uint surfaceClass;
};

uint pixelFlagsAt(ivec2 p) {
    uint v = uint(fetchTextureUniform(pc.flagsSlot, p, 0).r * 255.0 + 0.5);
    return v;
}

GBufferSample readGBuffer(ivec2 p) {
    GBufferSample g;
    vec4 n = fetchTextureUniform(pc.normalSlot, p, 0);
    uint bits = pixelFlagsAt(p);
    g.normal = normalize(n.xyz + vec3(0.0, 0.0, 1e-12));
    g.roughness = n.w;
    g.flags = bits & 15u;
    g.surfaceClass = bits >> PIXEL_CLASS_SHIFT;
    return g;
}

float sceneDepthAt(ivec2 p) { return fetchTextureUniform(pc.depthSlot, p, 0).r; }

// View distance along -Z of a reversed-Z perspective depth (the camera's proj: w = -z_view).
float linearDepth(FrameConstants f, float depth) {
    return f.proj[3][2] / max(depth + f.proj[2][2], 1e-12);
}

vec3 worldPositionAt(FrameConstants f, vec2 pixelCenter, float depth) {
    vec2 ndc = pixelCenter * f.invViewportSize * 2.0 - 1.0;
    vec4 p = f.invViewProj * vec4(ndc, depth, 1.0);
    return p.xyz / p.w;
}

vec3 viewDirectionAt(FrameConstants f, vec2 pixelCenter) {
    return normalize(worldPositionAt(f, pixelCenter, 0.5) - f.cameraPosition);
}
#endif
