// The ray-tracing frame record (FrameConstants::rt) as shaders reach it.
#ifndef SHADEL_RT_FRAME_GLSL
#define SHADEL_RT_FRAME_GLSL
#include "common/bindless.glsl"
#include "raytracing/rt_types.h"

layout(buffer_reference, scalar) readonly buffer RtFrameRef { RtFrame r; };
layout(buffer_reference, scalar) buffer RtCountersRef { RtCounters c; };
layout(buffer_reference, scalar) readonly buffer RtShadelObjectRefs { RtShadelObject o[]; };

// Unit normals as two numbers in [-1, 1] (octahedral): the RT cache stores its texels' normals.
vec2 rtOctEncode(vec3 n) {
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    vec2 e = n.xy;
    if (n.z < 0.0) e = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    return e;
}

vec3 rtOctDecode(vec2 e) {
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    if (n.z < 0.0) n.xy = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    return normalize(n);
}
#endif
