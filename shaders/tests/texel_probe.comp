#version 460
// Test probe of block-compressed textures: every texel of level 0 of a bindless slot, fetched
// (no filtering), into a buffer of one vec4 per texel, row-major: the device's decode, for the
// tests to compare with the CPU decoder's.
#include "common/bindless.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(push_constant, scalar) uniform Push {
    uint64_t result; // vec4 per texel
    uint slot;
    uint width;
    uint height;
} pc;

layout(buffer_reference, scalar) writeonly buffer Vec4Out { vec4 v[]; };

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= pc.width || p.y >= pc.height) return;
    Vec4Out(pc.result).v[p.y * pc.width + p.x] = fetchTextureUniform(pc.slot, ivec2(p), 0);
}
