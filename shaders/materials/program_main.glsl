// The engine's part of a material program stage after the author's code: finds this
// invocation's shadel in the program's chunk list, rebuilds its surface point (as
// shadel/shade.comp does for the built-in program) and runs the author's main. Shadels no
// triangle covers are written zero in every layer the program uses by its first stage.

// The program's i-th chunk in the shading queue, or false past the list's end.
bool materialWork(uint group, out GpuShadelWork work) {
    if (group >= Uvec4Buffer(pc.header).v[pc.program].w) return false;
    uint64_t list = pc.queues + uint64_t(pc.program) * pc.capacity * 4ul;
    work = ShadelWorkBuffer(gMaterialShadel.queue).w[UintBuffer(list).v[group]];
    return true;
}

void main() {
    gMaterialFrame = FrameConstantsRef(pc.frame).f;
    FrameConstants f = gMaterialFrame;
    gTextureFeedback = f.textureFeedback;
    gMaterialShadel = ShadelFrameRef(f.shadel).s;
    ShadelFrame s = gMaterialShadel;
    GpuShadelWork work;
    if (!materialWork(dispatch2dGroup(), work)) return;
    gMaterialWork = work;
    ShadelObjectRef o = shadelObject(s, work.object);
    uvec2 local = gl_LocalInvocationID.xy;
    gMaterialIndex = storageIndex(work.slot, local);
    uvec2 sheetShadel = uvec2(work.chunk & 0xFFFFu, work.chunk >> 16) * SHADEL_CHUNK + local;
    uvec2 size = levelSize(o, work.mip);
    uvec2 shadel = levelShadel(o, work.mip, sheetShadel);
    bool shading = all(lessThan(shadel, size));
    uint tri = shading ? triangleId(s, o.v.idMapOffset[work.mip] + shadel.y * size.x + shadel.x) : 0xFFFFu;
    shading = shading && tri != 0xFFFFu;
    GpuInstance inst = InstanceBuffer(f.instances).i[work.object];
    GpuMesh mesh = MeshBuffer(f.meshes).m[inst.mesh];
    material = MaterialBuffer(f.materials).m[inst.material];
    shading = shading && tri * 3u < mesh.indexCount;
    if (!shading) tri = 0u;
    IndexBuffer indices = IndexBuffer(f.indices);
    uint i0 = indices.i[mesh.firstIndex + tri * 3u] + uint(mesh.vertexOffset);
    uint i1 = indices.i[mesh.firstIndex + tri * 3u + 1u] + uint(mesh.vertexOffset);
    uint i2 = indices.i[mesh.firstIndex + tri * 3u + 2u] + uint(mesh.vertexOffset);
    Vec2Buffer uvs = Vec2Buffer(s.shadelUvs);
    ShadelBary bary = shadelBaryWithNeighbours(min(shadel, size - 1u), size, uvs.v[i0], uvs.v[i1], uvs.v[i2]);
    VertexBuffer vb = VertexBuffer(f.vertices);
    GpuVertex v0 = vb.v[i0], v1 = vb.v[i1], v2 = vb.v[i2];
    vec3 p = shadelInterpolate(bary.center, v0.position, v1.position, v2.position);
    vec3 pDx = shadelInterpolate(bary.right, v0.position, v1.position, v2.position);
    vec3 pDy = shadelInterpolate(bary.down, v0.position, v1.position, v2.position);
    vec3 n = shadelInterpolate(bary.center, v0.normal, v1.normal, v2.normal);
    vec3 t = shadelInterpolate(bary.center, v0.tangent.xyz, v1.tangent.xyz, v2.tangent.xyz);
    surface.position = (inst.model * vec4(p, 1.0)).xyz;
    surface.positionDx = mat3(inst.model) * (pDx - p);
    surface.positionDy = mat3(inst.model) * (pDy - p);
    surface.normal = normalize(mat3(inst.normalMatrix) * n);
    surface.tangent = vec4(mat3(inst.model) * t, v0.tangent.w);
    // UVs extrapolate to gutter shadels only as far as the triangle's own UV box (as in
    // shadel/shade.comp: further, a texture's REPEAT would read its far side).
    vec2 uv = shadelInterpolate2(bary.center, v0.uv0, v1.uv0, v2.uv0);
    surface.uv = clampToTriangleUv(uv, v0.uv0, v1.uv0, v2.uv0);
    surface.uvDx = shadelInterpolate2(bary.right, v0.uv0, v1.uv0, v2.uv0) - uv;
    surface.uvDy = shadelInterpolate2(bary.down, v0.uv0, v1.uv0, v2.uv0) - uv;
    surface.uv1 = clampToTriangleUv(shadelInterpolate2(bary.center, v0.uv1, v1.uv1, v2.uv1),
                                    v0.uv1, v1.uv1, v2.uv1);
    surface.geometricNormal = normalize(mat3(inst.normalMatrix) *
                                        cross(v1.position - v0.position, v2.position - v0.position));
    surface.frontFacing = dot(surface.geometricNormal, f.cameraPosition - surface.position) >= 0.0;
    surface.shadel = shadel;
    surface.levelSize = size;
    surface.object = work.object;
#if MATERIAL_STAGE_LAST
    // Reuse: where the chunk is seen from as it is shaded (shadel/shade.comp recordChunkView).
    if (s.reuse != 0u && gl_LocalInvocationIndex == CHUNK_CENTRE_SHADEL) {
        vec3 point = surface.position;
        bool seen = shading || chunkSurfacePoint(f, s, work, point);
        Uvec4Buffer(s.chunkViews).v[work.slot] = chunkViewRecord(seen, point, f.cameraPosition);
    }
#endif
    if (!shading) {
        if (MATERIAL_STAGE_INDEX == 0u) {
            storeRadiance(s.layers[SHADEL_LAYER_RADIANCE], gMaterialIndex, vec4(0.0));
            storeMaterial(s.layers[SHADEL_LAYER_MATERIAL], gMaterialIndex, vec4(0.0));
        }
        return;
    }
#if !MATERIAL_PROGRAM_WRITES_MATERIAL_LAYER
    // A program without the material layer leaves there what the built-in program would: the
    // base colour and roughness factors (GI injection and the layer:material view read it).
    if (MATERIAL_STAGE_INDEX == 0u)
        storeMaterial(s.layers[SHADEL_LAYER_MATERIAL], gMaterialIndex,
                      vec4(material.baseColorFactor.rgb, material.roughnessFactor));
#endif
    materialStageMain();
}
