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

void storeLayers(ShadelFrame s, ivec2 texel, vec4 radiance, vec4 material) {
    imageStore(gImagesRgba16f[s.layerWriteSlot[SHADEL_LAYER_RADIANCE]], texel, radiance);
    imageStore(gImagesRgba8[s.layerWriteSlot[SHADEL_LAYER_MATERIAL]], texel, material);
}

uint triangleId(ShadelFrame s, uint offset) {
    uint word = UintBuffer(s.idMaps).v[offset >> 1];
    return (word >> ((offset & 1u) * 16u)) & 0xFFFFu;
}

// Preserved layers (seed: "GetIndexPrevSampleVirtualCoords ... if it was computed last frame
// it's there"). Where last frame stored this chunk, returns its storage slot then; -1 when the
// chunk must be shaded: reuse off, the object's level changed (reuseLevels, decided on the
// CPU), or this chunk's turn to be refreshed (each chunk is reshaded once per refresh period,
// at its own phase, so view-dependent terms never lag for long). Uniform over the workgroup.
int carrySource(ShadelFrame s, GpuShadelObject o, GpuShadelWork work) {
    if (s.reuse == 0u || ((o.reuseLevels >> work.mip) & 1u) == 0u) return -1;
    if (shadelRefreshDue(s, o, work.chunk)) return -1;
    uvec2 sheet = uvec2(work.chunk & 0xFFFFu, work.chunk >> 16) * SHADEL_CHUNK;
    uint block = blockIndex(s, sheet);
    uint bit = chunkBit(sheet);
    uint64_t prevMask = Uint64Buffer(s.prevOccupancy).v[block];
    uint prevBase = UintBuffer(s.prevOffsetMap).v[block];
    if ((prevMask & (1ul << bit)) == 0ul || prevBase == SHADEL_INVALID) return -1;
    return int(chunkSlot(prevMask, prevBase, bit));
}

void carryOver(ShadelFrame s, uint fromSlot, ivec2 outTexel) {
    ivec2 from = storageTexel(s, fromSlot, gl_LocalInvocationID.xy);
    imageStore(gImagesRgba16f[s.layerWriteSlot[SHADEL_LAYER_RADIANCE]], outTexel,
               fetchTexture(s.prevLayerReadSlot[SHADEL_LAYER_RADIANCE], from, 0));
    imageStore(gImagesRgba8[s.layerWriteSlot[SHADEL_LAYER_MATERIAL]], outTexel,
               fetchTexture(s.prevLayerReadSlot[SHADEL_LAYER_MATERIAL], from, 0));
    if (gl_LocalInvocationIndex == 0u) atomicAdd(ShadelCountersRef(s.counters).c.chunksReused, 1u);
}

shared bool chunkNearChangedLight;

// Whether any shadel of the chunk lies within reach of a light that changed this frame (the
// object's bounds do, or this is not called). Only positions are rebuilt. Call in uniform flow.
bool chunkTouchesChangedLight(FrameConstants f, ShadelFrame s, GpuShadelObject o, GpuShadelWork work) {
    if (gl_LocalInvocationIndex == 0u) chunkNearChangedLight = false;
    barrier();
    uvec2 size = levelSize(o, work.mip);
    uvec2 shadel = uvec2(work.chunk & 0xFFFFu, work.chunk >> 16) * SHADEL_CHUNK +
                   gl_LocalInvocationID.xy - o.rect[work.mip].xy * SHADEL_BLOCK;
    uint tri = all(lessThan(shadel, size))
                   ? triangleId(s, o.idMapOffset[work.mip] + shadel.y * size.x + shadel.x)
                   : 0xFFFFu;
    if (tri != 0xFFFFu) {
        GpuInstance inst = InstanceBuffer(f.instances).i[work.object];
        GpuMesh mesh = MeshBuffer(f.meshes).m[inst.mesh];
        IndexBuffer indices = IndexBuffer(f.indices);
        uint i0 = indices.i[mesh.firstIndex + tri * 3u] + uint(mesh.vertexOffset);
        uint i1 = indices.i[mesh.firstIndex + tri * 3u + 1u] + uint(mesh.vertexOffset);
        uint i2 = indices.i[mesh.firstIndex + tri * 3u + 2u] + uint(mesh.vertexOffset);
        Vec2Buffer uvs = Vec2Buffer(s.shadelUvs);
        vec3 b = shadelBarycentrics(shadelCenterUv(shadel, size), uvs.v[i0], uvs.v[i1], uvs.v[i2]);
        VertexBuffer vb = VertexBuffer(f.vertices);
        vec3 p = shadelInterpolate(b, vb.v[i0].position, vb.v[i1].position, vb.v[i2].position);
        vec3 world = (inst.model * vec4(p, 1.0)).xyz;
        Vec4Buffer lights = Vec4Buffer(s.changedLights);
        for (uint i = 0u; i < s.changedLightCount; ++i) {
            vec4 l = lights.v[i];
            if (isinf(l.w) || distance(world, l.xyz) <= l.w) chunkNearChangedLight = true;
        }
    }
    barrier();
    return chunkNearChangedLight;
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    uint workIndex = gl_WorkGroupID.y * 32768u + gl_WorkGroupID.x;
    if (workIndex >= ShadelCountersRef(s.counters).c.shadeDispatch.w) return;
    GpuShadelWork work = ShadelWorkBuffer(s.queue).w[workIndex];
    GpuShadelObject o = ShadelObjectBuffer(s.objects).o[work.object];
    uvec2 local = gl_LocalInvocationID.xy;
    ivec2 outTexel = storageTexel(s, work.slot, local);
    // Chunks of objects a changed light reaches come here even when reusable (the fill pass
    // cannot tell which of their shadels the light reaches): carry over those it does not.
    int carrySlot = (o.flags & SHADEL_OBJECT_NEAR_CHANGED_LIGHT) != 0u ? carrySource(s, o, work) : -1;
    if (carrySlot >= 0 && chunkTouchesChangedLight(f, s, o, work)) carrySlot = -1;
    if (carrySlot >= 0) {
        carryOver(s, uint(carrySlot), outTexel);
        return;
    }

    uvec2 sheetShadel = uvec2(work.chunk & 0xFFFFu, work.chunk >> 16) * SHADEL_CHUNK + local;
    uvec2 size = levelSize(o, work.mip);
    uvec2 shadel = sheetShadel - o.rect[work.mip].xy * SHADEL_BLOCK;
    if (any(greaterThanEqual(shadel, size))) {
        storeLayers(s, outTexel, vec4(0.0), vec4(0.0));
        return;
    }
    uint tri = triangleId(s, o.idMapOffset[work.mip] + shadel.y * size.x + shadel.x);
    if (tri == 0xFFFFu) { // gutter no filter reads: nothing to shade
        storeLayers(s, outTexel, vec4(0.0), vec4(0.0));
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
    vec4 material;
    vec3 color = prefilteredShade(f, mat, si, shadelCenterUv(shadel, size), vec2(1.0) / vec2(size),
                                  uvs.v[i0], uvs.v[i1], uvs.v[i2], v0.uv0, v1.uv0, v2.uv0,
                                  s.materialSamples, uvec3(shadel, work.object * 16u + work.mip),
                                  material);
    storeLayers(s, outTexel, vec4(color, 1.0), material);
}
