// Vertex pulling from the unified geometry buffer, shared by every raster pass.
#ifndef SHADEL_VERTEX_GLSL
#define SHADEL_VERTEX_GLSL
#include "common/bindless.glsl"

struct WorldVertex {
    vec3 position;
    vec3 normal;
    vec4 tangent;
    vec2 uv0;
    vec2 uv1;
};

WorldVertex fetchWorldVertex(FrameConstants f, GpuInstance inst, uint vertexIndex) {
    GpuVertex v = VertexBuffer(f.vertices).v[vertexIndex];
    WorldVertex o;
    o.position = (inst.model * vec4(v.position, 1.0)).xyz;
    o.normal = normalize(mat3(inst.normalMatrix) * v.normal);
    o.tangent = vec4(normalize(mat3(inst.model) * v.tangent.xyz + vec3(1e-9)), v.tangent.w);
    o.uv0 = v.uv0;
    o.uv1 = v.uv1;
    return o;
}
#endif
