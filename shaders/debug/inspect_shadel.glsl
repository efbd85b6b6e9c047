// --inspect on the decoupled path: which shadels the pixel reads (LOD, the first tap's chunk and
// storage slot) and what came back. Shared by the raster reconstruction and the compute resolve;
// both then print the surface (debug/inspect.glsl) as the forward fallback would shade it.
#ifndef SHADEL_INSPECT_SHADEL_GLSL
#define SHADEL_INSPECT_SHADEL_GLSL
#include "shadel/resolve.glsl"
#include "debug/inspect.glsl"

void inspectShadels(FrameConstants f, ShadelFrame s, ShadelObjectRef o, Reconstruction r,
                    vec2 shadelUv, vec2 texelDx, vec2 texelDy) {
    ShadelLevels l = shadelLevels(o, texelDx, texelDy, s.shadingBias, s.trilinearBand);
    fitLevelsToWindows(o, shadelUv, l); // the levels the reconstruction read
    shaderPrintF4(f, PRINT_SHADEL_LOD, vec4(r.lod, float(l.mip0), float(l.mip1), l.blend));
    // Why the LOD is coarser than the footprint: the frame's bias (--shading-bias + the capacity
    // controller) and the object's material rate (render/shadel/material_rate.h), which a
    // textured material takes no coarser than its texture LOD (texture_rate.h).
    shaderPrintF3(f, PRINT_SHADING_BIAS, vec3(s.shadingBias, o.v.rateBias, o.v.textureLod));
    ivec2 t0;
    vec2 w;
    bilinearFootprint(o, r.mip0, shadelUv, t0, w);
    uvec2 sheet = sheetShadel(o, r.mip0, t0);
    uint block = blockIndex(s, sheet);
    uint64_t mask = Uint64Buffer(s.occupancy).v[block];
    uint base = UintBuffer(s.offsetMap).v[block];
    uint bit = chunkBit(sheet);
    bool stored = (mask & (1ul << bit)) != 0ul && base != SHADEL_INVALID;
    uint slot = stored ? chunkSlot(mask, base, bit) : SHADEL_INVALID;
    shaderPrintU4(f, PRINT_SHADEL_CHUNK, uvec4(sheet / SHADEL_CHUNK, slot, r.mip0));
    shaderPrintF3(f, PRINT_RECONSTRUCTED, r.color);
}
#endif
