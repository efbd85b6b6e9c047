#version 460
// One level of the depth pyramid for occlusion culling (render/culling). Level 0 copies the
// prepass depth; each next level (ceil-halved) keeps the farthest depth (reversed Z: the
// smallest) of the 2 x 2 texels below it, the last row or column alone at odd edges, so every
// texel of a level covers exactly the pixels beneath it.
#include "culling/cull.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant, scalar) uniform Push {
    uint64_t pyramid; // float[], every level packed
    uint srcOffset;
    uint dstOffset;
    uvec2 srcSize;
    uvec2 dstSize;
    uint depthSlot; // the scene depth (sampled), read for level 0
    uint fromDepth; // 1: level 0
} pc;

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(p, pc.dstSize))) return;
    FloatBuffer pyramid = FloatBuffer(pc.pyramid);
    float farthest;
    if (pc.fromDepth != 0u) {
        farthest = fetchTextureUniform(pc.depthSlot, ivec2(p), 0).r;
    } else {
        uvec2 a = 2u * p, b = min(a + 1u, pc.srcSize - 1u);
        uint row0 = pc.srcOffset + a.y * pc.srcSize.x, row1 = pc.srcOffset + b.y * pc.srcSize.x;
        farthest = min(min(pyramid.v[row0 + a.x], pyramid.v[row0 + b.x]),
                       min(pyramid.v[row1 + a.x], pyramid.v[row1 + b.x]));
    }
    pyramid.v[pc.dstOffset + p.y * pc.dstSize.x + p.x] = farthest;
}
