#version 460
// GPU skinning (render/skinning): one thread per skinned vertex. Its unskinned vertex (morph
// targets applied) goes through sum(weight x joint matrix), as the importer's CPU skinning does
// (scene/gltf_import.cpp: the normal by the inverse transpose, the tangent by the matrix), then
// the normal is normalized and the tangent made orthonormal to it (mesh_utils'
// sanitizeNormalsAndTangents), and the result written to the deformed vertex buffer.
#include "common/bindless.glsl"

layout(local_size_x = 64) in;

struct SkinVertex {
    uint target;  // index into the deformed buffer
    uvec4 joints; // into the joint matrices of every skin, laid end to end
    vec4 weights;
};
layout(buffer_reference, scalar) readonly buffer SkinVertexBuffer { SkinVertex v[]; };
layout(buffer_reference, scalar) readonly buffer MatrixBuffer { mat4 m[]; };
layout(buffer_reference, scalar) writeonly buffer DeformedBuffer { GpuVertex v[]; };

layout(push_constant, scalar) uniform Push {
    uint64_t bindVertices;
    uint64_t skinVertices;
    uint64_t matrices;
    uint64_t deformed;
    uint count;
} pc;

vec3 anyPerpendicular(vec3 n) {
    vec3 axis = abs(n.x) < 0.9 ? vec3(1, 0, 0) : vec3(0, 1, 0);
    return normalize(cross(axis, n));
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    SkinVertex s = SkinVertexBuffer(pc.skinVertices).v[i];
    GpuVertex b = VertexBuffer(pc.bindVertices).v[i];
    MatrixBuffer joints = MatrixBuffer(pc.matrices);
    mat4 m = joints.m[s.joints.x] * s.weights.x + joints.m[s.joints.y] * s.weights.y +
             joints.m[s.joints.z] * s.weights.z + joints.m[s.joints.w] * s.weights.w;
    GpuVertex o;
    o.position = (m * vec4(b.position, 1.0)).xyz;
    vec3 n = normalize(transpose(inverse(mat3(m))) * b.normal);
    vec3 t = mat3(m) * b.tangent.xyz;
    t -= n * dot(n, t);
    float len = length(t);
    o.normal = n;
    o.tangent = vec4(len > 1e-6 ? t / len : anyPerpendicular(n), b.tangent.w);
    o.uv0 = b.uv0;
    o.uv1 = b.uv1;
    DeformedBuffer(pc.deformed).v[s.target] = o;
}
