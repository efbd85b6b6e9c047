#version 460
// The scene depth copied into the depth-stencil target of the stencil-culled effects (the scene
// depth has no stencil aspect), so their stencil marks are depth-tested exactly as the prepass
// resolved visibility.
#define SCREEN_SPACE_FRAGMENT // no tile lists here
#include "screenspace/screen_space.glsl"

layout(location = 0) out float outMask; // the character mask: colour writes are masked off

void main() {
    gl_FragDepth = sceneDepthAt(ivec2(gl_FragCoord.xy));
    outMask = 0.0;
}
