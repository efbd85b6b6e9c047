#version 460
// Decal culling, forward half (render/decals): one 16x16 workgroup per 16x16-pixel tile, the
// tile's depth-bounded frustum (as the light tiles build it, lighting/tile_cull.comp) against
// every decal meeting the camera frustum; one list per decal stage.
#include "decals/decal_cull.glsl"

layout(local_size_x = 16, local_size_y = 16) in;
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
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (all(lessThan(pixel, ivec2(f.viewportSize)))) {
        float d = fetchTextureUniform(pc.depthSlot, pixel, 0).r;
        if (d > 0.0) { // reversed Z: 0 is the sky
            atomicMin(sDepthMin, floatBitsToUint(d));
            atomicMax(sDepthMax, floatBitsToUint(d));
        }
    }
    barrier();
    if (sDepthMax == 0u) { // nothing but sky
        clearDecalLists(df.tileRanges, tile);
        return;
    }
    vec2 lo = vec2(gl_WorkGroupID.xy * LIGHT_TILE_SIZE) * f.invViewportSize * 2.0 - 1.0;
    vec2 hi = min(vec2((gl_WorkGroupID.xy + 1u) * LIGHT_TILE_SIZE) * f.invViewportSize, vec2(1.0)) * 2.0 - 1.0;
    float dNear = uintBitsToFloat(sDepthMax), dFar = uintBitsToFloat(sDepthMin);
    vec3 corners[8];
    for (int i = 0; i < 8; ++i) {
        vec4 clip = vec4((i & 1) != 0 ? hi.x : lo.x, (i & 2) != 0 ? hi.y : lo.y,
                         (i & 4) != 0 ? dFar : dNear, 1.0);
        vec4 w = f.invViewProj * clip;
        corners[i] = w.xyz / w.w;
    }
    // Side planes through the eye, then near and far along the view direction.
    vec3 eye = f.cameraPosition;
    vec3 centre = vec3(0.0);
    for (int i = 0; i < 8; ++i) centre += corners[i] * 0.125;
    vec4 planes[6];
    const ivec2 edges[4] = ivec2[4](ivec2(0, 1), ivec2(1, 3), ivec2(3, 2), ivec2(2, 0));
    for (int e = 0; e < 4; ++e) {
        vec3 n = normalize(cross(corners[edges[e].x + 4] - eye, corners[edges[e].y + 4] - eye));
        if (dot(n, centre - eye) < 0.0) n = -n;
        planes[e] = vec4(n, -dot(n, eye));
    }
    vec3 forward = normalize(-vec3(f.view[0][2], f.view[1][2], f.view[2][2]));
    float zMin = 1e30, zMax = -1e30;
    for (int i = 0; i < 8; ++i) {
        float z = dot(corners[i] - eye, forward);
        zMin = min(zMin, z), zMax = max(zMax, z);
    }
    planes[4] = vec4(forward, -dot(forward, eye) - zMin);
    planes[5] = vec4(-forward, dot(forward, eye) + zMax);
    vec3 boxMin = corners[0], boxMax = corners[0];
    for (int i = 1; i < 8; ++i) boxMin = min(boxMin, corners[i]), boxMax = max(boxMax, corners[i]);

    DECAL_CULL_LOOP(df, 256u, decalInsidePlanes(d, planes) && decalMeetsBox(d, boxMin, boxMax))
    writeDecalLists(df, df.tileRanges, tile, 256u);
}
