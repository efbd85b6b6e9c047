#version 460
// Decal culling, forward half (render/decals): one workgroup per 16x16-pixel tile, the tile's
// depth-bounded frustum (common/tile_frustum.glsl, as the light tiles build it) against every
// decal meeting the camera frustum; one list per decal stage.
#include "decals/decal_cull.glsl"
#include "common/tile_frustum.glsl"
#extension GL_KHR_shader_subgroup_arithmetic : require

layout(local_size_x = TILE_CULL_SIDE, local_size_y = TILE_CULL_SIDE) in;
layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint depthSlot;
} pc;

shared uint sDepthMin, sDepthMax;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    DecalFrame df = DecalFrameRef(f.decals).d;
    uint tid = gl_LocalInvocationIndex;
    uint tile = gl_WorkGroupID.y * df.tilesX + gl_WorkGroupID.x;
    if (tid == 0u) {
        sDepthMin = 0xFFFFFFFFu;
        sDepthMax = 0u;
        sDecalCount = 0u;
    }
    barrier();
    // Depth bounds of the tile's covered pixels (reversed Z: 0 is the sky), reduced over the
    // subgroup first, one shared atomic per subgroup.
    uint depthMin = 0xFFFFFFFFu, depthMax = 0u;
    for (uint q = 0u; q < 4u; ++q) {
        ivec2 pixel = tileCullPixel(q);
        if (all(lessThan(pixel, ivec2(f.viewportSize))))
            tileDepthBoundsAdd(fetchTextureUniform(pc.depthSlot, pixel, 0).r, depthMin, depthMax);
    }
    depthMin = subgroupMin(depthMin);
    depthMax = subgroupMax(depthMax);
    if (subgroupElect() && depthMax != 0u) {
        atomicMin(sDepthMin, depthMin);
        atomicMax(sDepthMax, depthMax);
    }
    barrier();
    if (sDepthMax == 0u) { // nothing but sky
        clearDecalLists(df.tileRanges, tile);
        return;
    }
    TileFrustum t = tileFrustum(f, gl_WorkGroupID.xy, uintBitsToFloat(sDepthMax), uintBitsToFloat(sDepthMin));
    vec4 planes[6] = t.planes;
    vec3 boxMin = t.boxMin, boxMax = t.boxMax;

    DECAL_CULL_LOOP(df, TILE_CULL_THREADS, decalInsidePlanes(d, planes) && decalMeetsBox(d, boxMin, boxMax))
    writeDecalLists(df, df.tileRanges, tile, TILE_CULL_THREADS);
}
