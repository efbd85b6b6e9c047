#version 460
// Distance-field sun visibility and ambient occlusion per surface pixel (tiles with a surface),
// next to the shadow map's visibility at the same point (for the comparison the stats report).
// The composite applies the AO; the DF sun visibility is what the far range beyond the shadow
// map would use.
#include "screenspace/screen_space.glsl"
#include "distance_fields/distance_fields.glsl"
#include "common/lighting.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

void main() {
    uvec2 tile = currentTile(pc.tiles, pc.listOffset);
    ivec2 p = ivec2(tile * TILE_SIZE + gl_LocalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) return;
    GBufferSample g = readGBuffer(p);
    if ((g.flags & PIXEL_SURFACE) == 0u) return;
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    DistanceFieldFrame df = DistanceFieldFrameRef(pc.distanceFields).d;
    vec3 position = worldPositionAt(f, vec2(p) + 0.5, sceneDepthAt(p));
    vec3 toSun = -f.sunDirection;
    bool facing = dot(g.normal, toSun) > 0.0;
    float lit = facing ? dfSoftShadow(df, position + (g.normal + toSun) * 0.04, toSun, 400.0) : 0.0;
    float mapped = facing ? sunShadow(f, position, g.normal) : 0.0;
    float ao = dfAmbientOcclusion(df, position + g.normal * 0.02, g.normal);
    // Alpha: 1 where both shadows are defined and not trivially 0 (the surface faces the sun),
    // 0.5 on the other surfaces, 0 (cleared) elsewhere.
    imageStore(gImagesRgba8[pc.dfSlot], p, vec4(lit, mapped, ao, facing ? 1.0 : 0.5));
}
