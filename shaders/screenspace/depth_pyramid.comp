#version 460
// The closest-depth pyramid of the SSR march: level 0 is the scene depth, each level above keeps
// the nearest (largest, reversed Z) of its 2x2 texels below. A march may skip a cell whose
// nearest depth lies behind the ray. Depths are stored as their bits (non-negative floats
// order as their bit patterns), one level per dispatch.
#include "screenspace/screen_space.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

void main() {
    uint level = pc.level;
    uvec2 size = uvec2(max(pc.width >> level, 1u), max(pc.height >> level, 1u));
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(size.x) || p.y >= int(size.y)) return;
    uint closest;
    if (level == 0u) {
        closest = floatBitsToUint(max(sceneDepthAt(p), 0.0));
    } else {
        uvec2 below = uvec2(max(pc.width >> (level - 1u), 1u), max(pc.height >> (level - 1u), 1u));
        uint src = pc.pyramid[level - 1u];
        closest = 0u;
        // An odd-sized level below has a last row/column no 2x2 block covers: fold it in.
        int xs = (p.x == int(size.x) - 1 && (below.x & 1u) != 0u) ? 3 : 2;
        int ys = (p.y == int(size.y) - 1 && (below.y & 1u) != 0u) ? 3 : 2;
        for (int y = 0; y < ys; ++y)
            for (int x = 0; x < xs; ++x) {
                ivec2 q = min(p * 2 + ivec2(x, y), ivec2(below) - 1);
                closest = max(closest, imageLoad(gImagesR32ui[src], q).r);
            }
    }
    imageStore(gImagesR32ui[pc.pyramid[level]], p, uvec4(closest));
}
