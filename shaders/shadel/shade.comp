#version 460
// Shading (seed: "Shadel Shader"): one 8x8 workgroup per queued chunk. Each shadel finds its
// triangle in the object's triangle-ID map, rebuilds the surface from the triangle's vertices
// with clamped barycentrics (and the barycentrics one shadel right and down, for derivatives),
// then runs the same material and lighting code as the forward path.
#include "shadel/shadel.glsl"
#include "common/lighting.glsl"
#include "common/shadel_bary.h"
#include "shadel/prefilter.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

uint triangleId(ShadelFrame s, uint offset) {
    uint word = UintBuffer(s.idMaps).v[offset >> 1];
    return (word >> ((offset & 1u) * 16u)) & 0xFFFFu;
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    uint workIndex = gl_WorkGroupID.y * 32768u + gl_WorkGroupID.x;
    if (workIndex >= ShadelCountersRef(s.counters).c.shadeDispatch.w) return;
    GpuShadelWork work = ShadelWorkBuffer(s.queue).w[workIndex];
    if (work.slot == SHADEL_INVALID) return; // part of a block that overflowed storage
    GpuShadelObject o = ShadelObjectBuffer(s.objects).o[work.object];
    uvec2 local = gl_LocalInvocationID.xy;
    ivec2 outTexel = storageTexel(s, work.slot, local);

    uvec2 sheetShadel = uvec2(work.chunk & 0xFFFFu, work.chunk >> 16) * SHADEL_CHUNK + local;
    uvec2 size = levelSize(o, work.mip);
    uvec2 shadel = sheetShadel - o.rect[work.mip].xy * SHADEL_BLOCK;
    if (any(greaterThanEqual(shadel, size))) {
        imageStore(gImagesRgba16f[s.storageWriteSlot], outTexel, vec4(0.0));
        return;
    }
    uint tri = triangleId(s, o.idMapOffset[work.mip] + shadel.y * size.x + shadel.x);
    if (tri == 0xFFFFu) { // gutter no filter reads: nothing to shade
        imageStore(gImagesRgba16f[s.storageWriteSlot], outTexel, vec4(0.0));
        return;
    }
    GpuInstance inst = InstanceBuffer(f.instances).i[work.object];
    GpuMesh mesh = MeshBuffer(f.meshes).m[inst.mesh];
    SHADEL_ASSERT(f, tri * 3u < mesh.indexCount, ASSERT_TRIANGLE_ID, tri, mesh.indexCount);
    IndexBuffer indices = IndexBuffer(f.indices);
    uint i0 = indices.i[mesh.firstIndex + tri * 3u] + uint(mesh.vertexOffset);
    uint i1 = indices.i[mesh.firstIndex + tri * 3u + 1u] + uint(mesh.vertexOffset);
    uint i2 = indices.i[mesh.firstIndex + tri * 3u + 2u] + uint(mesh.vertexOffset);
    Vec2Buffer uvs = Vec2Buffer(s.shadelUvs);
    ShadelBary bary = shadelBaryWithNeighbours(shadel, size, uvs.v[i0], uvs.v[i1], uvs.v[i2]);

    VertexBuffer vb = VertexBuffer(f.vertices);
    GpuVertex v0 = vb.v[i0], v1 = vb.v[i1], v2 = vb.v[i2];
    vec3 p = shadelInterpolate(bary.center, v0.position, v1.position, v2.position);
    vec3 n = shadelInterpolate(bary.center, v0.normal, v1.normal, v2.normal);
    vec4 tangent = vec4(shadelInterpolate(bary.center, v0.tangent.xyz, v1.tangent.xyz, v2.tangent.xyz), v0.tangent.w);
    vec2 uv = shadelInterpolate2(bary.center, v0.uv0, v1.uv0, v2.uv0);
    vec2 uvDx = shadelInterpolate2(bary.right, v0.uv0, v1.uv0, v2.uv0) - uv;
    vec2 uvDy = shadelInterpolate2(bary.down, v0.uv0, v1.uv0, v2.uv0) - uv;

    SurfaceInput si;
    si.position = (inst.model * vec4(p, 1.0)).xyz;
    si.normal = normalize(mat3(inst.normalMatrix) * n);
    si.tangent = vec4(mat3(inst.model) * tangent.xyz, tangent.w);
    si.uv = uv;
    si.uvDx = uvDx;
    si.uvDy = uvDy;
    // No rasterizer here: a surface faces the viewer when its normal points at the camera.
    vec3 geometricNormal = normalize(mat3(inst.normalMatrix) *
                                     cross(v1.position - v0.position, v2.position - v0.position));
    si.frontFacing = dot(geometricNormal, f.cameraPosition - si.position) >= 0.0;
    GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
    // The shadel's whole footprint, not its centre (prefilter.glsl; --material-samples caps it).
    vec3 color = prefilteredShade(f, mat, si, shadelCenterUv(shadel, size), vec2(1.0) / vec2(size),
                                  uvs.v[i0], uvs.v[i1], uvs.v[i2], v0.uv0, v1.uv0, v2.uv0,
                                  s.materialSamples, uvec3(shadel, work.object * 16u + work.mip));
    imageStore(gImagesRgba16f[s.storageWriteSlot], outTexel, vec4(color, 1.0));
}
