// What a pixel no surface covers shows: the environment seen along the pixel's view ray, or the
// solid --background colour (FrameConstants::backgroundColor, the radiance the display curve
// turns into that colour). Shared by every pass that writes uncovered pixels: the background
// draw of the colour passes, the compute resolve, tiled forward shading, the screen-space sky.
#ifndef SHADEL_BACKGROUND_GLSL
#define SHADEL_BACKGROUND_GLSL
#include "common/bindless.glsl"
#include "environment/environment.glsl"

// The world-space direction through a pixel centre of the internal-resolution target.
vec3 viewRayAt(FrameConstants f, vec2 pixelCenter) {
    vec2 ndc = pixelCenter * f.invViewportSize * 2.0 - 1.0;
    vec4 far = f.invViewProj * vec4(ndc, 0.5, 1.0);
    return normalize(far.xyz / far.w - f.cameraPosition);
}

vec3 backgroundAt(FrameConstants f, vec2 pixelCenter) {
    if (f.backgroundEnvironment == 0u) return f.backgroundColor;
    return environmentBackground(f.environment, viewRayAt(f, pixelCenter));
}
#endif
