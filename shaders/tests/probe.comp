#version 460
// Test probe: reads texel (0,0) of a bindless slot into a buffer and raises a shader assert
// when asked, so tests can check the bindless table and the message channel from the GPU side.
#include "common/bindless.glsl"

layout(local_size_x = 1) in;
layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t result; // vec4
    uint slot;
    uint raiseAssert;
} pc;

layout(buffer_reference, scalar) buffer Vec4Out { vec4 v; };

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    Vec4Out(pc.result).v = fetchTexture(pc.slot, ivec2(0), 0);
    SHADEL_ASSERT(f, pc.raiseAssert == 0u, ASSERT_TEST, 42u, pc.slot);
}
