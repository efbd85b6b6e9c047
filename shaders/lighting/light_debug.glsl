// Debug views of light culling, for whichever list shadeSurface just used (a tile's in forward
// shading, a chunk's in shadel shading): --visualize light-count (heat of the list's length)
// and --visualize blockers (red where some (light, blocker) pair is tested per pixel).
#ifndef SHADEL_LIGHT_DEBUG_GLSL
#define SHADEL_LIGHT_DEBUG_GLSL
#include "lighting/light_cull.glsl"

vec3 visualizeLighting(FrameConstants f, vec3 color) {
    if (f.visualize == VISUALIZE_LIGHT_COUNT) return lightCountHeat(lightListLength(f));
    if (f.visualize == VISUALIZE_BLOCKERS) {
        bool perPixel = false;
        uint n = lightListLength(f);
        for (uint i = 0u; i < n; ++i) {
            uvec2 e = lightListEntry(f, i);
            perPixel = perPixel || (e.x != LIGHT_INVALID && e.y != 0u);
        }
        float l = dot(color, vec3(0.2126, 0.7152, 0.0722));
        vec3 grey = vec3(l / (1.0 + l));
        return perPixel ? mix(grey, vec3(1.0, 0.1, 0.05), 0.6) : grey;
    }
    return color;
}
#endif
