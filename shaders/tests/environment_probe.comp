#version 460
// Test probe of shaders/environment/environment.glsl: for each (direction, roughness) it writes
// the irradiance, the specular and the background along the direction, and the BRDF table at
// (n.v = |direction.y|, roughness), as four vec4s.
#include "environment/environment.glsl"

layout(local_size_x = 64) in;
layout(buffer_reference, scalar) readonly buffer EnvironmentRef { GpuEnvironment e; };
layout(buffer_reference, scalar) readonly buffer Vec4In { vec4 v[]; };
layout(buffer_reference, scalar) writeonly buffer Vec4Out { vec4 v[]; };
layout(push_constant, scalar) uniform Push {
    uint64_t environment;
    uint64_t queries; // vec4: direction, perceptual roughness
    uint64_t results; // vec4 x 4 per query
    uint count;
} pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    GpuEnvironment e = EnvironmentRef(pc.environment).e;
    vec4 q = Vec4In(pc.queries).v[i];
    Vec4Out out_ = Vec4Out(pc.results);
    out_.v[4 * i + 0] = vec4(environmentIrradiance(e, q.xyz), 1.0);
    out_.v[4 * i + 1] = vec4(environmentSpecular(e, q.xyz, q.w), 1.0);
    out_.v[4 * i + 2] = vec4(environmentBackground(e, q.xyz), 1.0);
    // The table at n.v = |direction.y|, roughness q.w.
    out_.v[4 * i + 3] = vec4(environmentBrdf(e, abs(q.y), q.w), 1.0);
}
