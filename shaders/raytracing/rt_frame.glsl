// The ray-tracing frame record (FrameConstants::rt) as shaders reach it.
#ifndef SHADEL_RT_FRAME_GLSL
#define SHADEL_RT_FRAME_GLSL
#include "common/bindless.glsl"
#include "raytracing/rt_types.h"

layout(buffer_reference, scalar) readonly buffer RtFrameRef { RtFrame r; };
layout(buffer_reference, scalar) buffer RtCountersRef { RtCounters c; };
#endif
