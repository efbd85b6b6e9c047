#version 460
// Shadel path: traces the RT cache (render/raytracing/rt_shadel_cache.h). One 8x8 workgroup
// per tile of a visible instance's rect, one thread per texel of its shadel space at the cache's
// MIP. Only texels this frame's marking marked are traced (the pass runs between marking and
// shading): a texel in the view frustum but hidden behind other surfaces waits until it is
// seen. The texel's triangle (the level's triangle-ID map) and clamped barycentrics rebuild the
// surface as the shading pass does, then --rays-per-shadel AO and GI rays (and the sun's) are
// traced and averaged into the history, each frame continuing the texel's low-discrepancy
// sequence where the last one stopped.
#include "raytracing/rt_effects.glsl"
#include "common/shadel_bary.h"
#include "shadel/shadel.glsl"
#include "common/dispatch_2d.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;
layout(buffer_reference, scalar) readonly buffer RtShadelTiles { RtShadelTile t[]; };

uint cachedTriangle(ShadelFrame s, uint offset) {
    uint word = UintBuffer(s.idMaps).v[offset >> 1];
    return (word >> ((offset & 1u) * 16u)) & 0xFFFFu;
}

// The texel's triangle (0xFFFF: no surface), from the level's triangle-ID map.
uint texelTriangle(ShadelFrame s, RtShadelObject o, uvec2 texel) {
    return cachedTriangle(s, o.idMapOffset + texel.y * o.size.x + texel.x);
}

// A 2x2 block of texels finer on screen than the cache's MIP was chosen for
// (RtFrame::shadelTexelPixelScale: the far part of a large object whose nearest point set the
// MIP) is traced by one of its texels (`turn`: the first with a surface; `surfaces`: a bit each)
// into a history its texels share, as a texel of the next coarser MIP would be. Decided from
// that texel, so the block's four threads agree. (A turn rotating over the block's texels
// frame by frame was tried: two 256-ray references of one view, 4 x 64 and 8 x 32 rays, then
// differed by 28 dB, against 48 dB with the fixed texel; not understood, so left out.)
struct BlockTurn {
    bool finer;
    uint turn;
    uint surfaces;
};

BlockTurn blockTurn(FrameConstants f, RtFrame rt, ShadelFrame s, RtShadelObject o, uint object,
                    uvec2 block) {
    BlockTurn b = BlockTurn(false, 0u, 0u);
    bool decided = false;
    for (uint k = 0u; k < 4u; ++k) {
        uvec2 texel = block * 2u + uvec2(k & 1u, k >> 1u);
        if (any(greaterThanEqual(texel, o.size))) continue;
        uint tri = texelTriangle(s, o, texel);
        if (tri == 0xFFFFu) continue;
        b.surfaces |= 1u << k;
        if (decided) continue;
        decided = true;
        GpuInstance inst = InstanceBuffer(f.instances).i[object];
        GpuMesh mesh = MeshBuffer(f.meshes).m[inst.mesh];
        IndexBuffer indices = IndexBuffer(f.indices);
        uint i0 = indices.i[mesh.firstIndex + tri * 3u] + uint(mesh.vertexOffset);
        uint i1 = indices.i[mesh.firstIndex + tri * 3u + 1u] + uint(mesh.vertexOffset);
        uint i2 = indices.i[mesh.firstIndex + tri * 3u + 2u] + uint(mesh.vertexOffset);
        VertexBuffer vb = VertexBuffer(f.vertices);
        Vec2Buffer uvs = Vec2Buffer(s.shadelUvs);
        vec3 e1 = (inst.model * vec4(vb.v[i1].position - vb.v[i0].position, 0.0)).xyz;
        vec3 e2 = (inst.model * vec4(vb.v[i2].position - vb.v[i0].position, 0.0)).xyz;
        vec2 u1 = (uvs.v[i1] - uvs.v[i0]) * vec2(o.size), u2 = (uvs.v[i2] - uvs.v[i0]) * vec2(o.size);
        float texels = abs(u1.x * u2.y - u1.y * u2.x); // the triangle's area in texels, x2
        float side = sqrt(length(cross(e1, e2)) / max(texels, 1e-12)); // a texel's, world units
        vec3 bary = shadelBarycentrics(shadelCenterUv(texel, o.size), uvs.v[i0], uvs.v[i1], uvs.v[i2]);
        bary = max(bary, vec3(0.0));
        bary /= max(bary.x + bary.y + bary.z, 1e-6);
        vec3 p = (inst.model * vec4(shadelInterpolate(bary, vb.v[i0].position, vb.v[i1].position,
                                                      vb.v[i2].position), 1.0)).xyz;
        b.finer = side * rt.shadelTexelPixelScale < length(f.cameraPosition - p);
    }
    b.turn = b.surfaces == 0u ? 0u : uint(findLSB(b.surfaces));
    return b;
}

// Writes the texel, or, given its block's texels (a bit each), those of its 2x2 block.
void storeTerms(RtFrame rt, RtShadelObject o, uvec2 texel, uint blockTexels, vec4 terms, vec4 indirect) {
    for (uint k = 0u; k < (blockTexels != 0u ? 4u : 1u); ++k) {
        uvec2 t = blockTexels != 0u ? (texel & ~1u) + uvec2(k & 1u, k >> 1u) : texel;
        if (blockTexels != 0u && (blockTexels & (1u << k)) == 0u) continue;
        imageStore(gImagesRgba16f[rt.shadelTermsWrite], ivec2(o.origin + t), terms);
        imageStore(gImagesRgba16f[rt.shadelIndirectWrite], ivec2(o.origin + t), indirect);
    }
}

void storeSpots(RtFrame rt, RtShadelObject o, uvec2 texel, uint blockTexels, uvec4 spots) {
    for (uint k = 0u; k < (blockTexels != 0u ? 4u : 1u); ++k) {
        uvec2 t = blockTexels != 0u ? (texel & ~1u) + uvec2(k & 1u, k >> 1u) : texel;
        if (blockTexels != 0u && (blockTexels & (1u << k)) == 0u) continue;
        imageStore(gImagesRgba32ui[rt.shadelSpotWrite], ivec2(o.origin + t), spots);
    }
}

// Whether this frame's marking marked a chunk over shadel-UV `uv` of the object at any of its
// levels (the texel is seen, near enough to its centre: chunks are 8 shadels wide). Instances
// shaded forward (hybrid) have no marks: always.
bool shadelMarkedAt(ShadelFrame s, uint object, vec2 uv) {
    ShadelObjectRef o = shadelObject(s, object);
    if ((o.v.flags & SHADEL_OBJECT_DECOUPLED) == 0u) return true;
    Uint64Buffer occupancy = Uint64Buffer(s.occupancy);
    for (uint mip = o.v.firstMip; mip < o.v.mipCount; ++mip) {
        if (!windowHolds(o, mip, uv)) continue;
        uvec2 sheet = sheetShadel(o, mip, ivec2(floor(uv * vec2(levelSize(o, mip)))));
        if ((occupancy.v[blockIndex(s, sheet)] & (1ul << chunkBit(sheet))) != 0ul) return true;
    }
    return false;
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    RtFrame rt = RtFrameRef(f.rt).r;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    uint tileIndex = dispatch2dGroup();
    if (tileIndex >= rt.shadelTileCount) return;
    RtShadelTile tile = RtShadelTiles(rt.shadelTiles).t[tileIndex];
    RtShadelObject o = RtShadelObjectRefs(rt.shadelObjects).o[tile.object];
    uvec2 texel = uvec2(tile.tile & 0xFFFFu, tile.tile >> 16) * 8u + gl_LocalInvocationID.xy;
    if (any(greaterThanEqual(texel, o.size))) return;
    ivec2 atlas = ivec2(o.origin + texel);
    bool reset = (o.flags & RT_SHADEL_RESET) != 0u;
    // Blocks finer than needed (far parts of large objects) trace one texel into the history
    // the block's texels share: as many rays as a texel of the MIP they should have had. Texels
    // without a surface are written empty by their own threads below.
    // Not with hard traced shadows (the sun's or the spots'): exact per point, they would lose
    // resolution (the skinned strip's shadow fell from 46.6 to 42.2 dB against its map).
    bool hardShadows = rt.shadows != 0u && rt.shadowRays == 1u;
    BlockTurn block = hardShadows ? BlockTurn(false, 0u, 0u)
                                  : blockTurn(f, rt, s, o, tile.object, texel >> 1u);
    uint self = (texel.x & 1u) + 2u * (texel.y & 1u);
    bool blockShared = block.finer && !hardShadows && (block.surfaces & (1u << self)) != 0u;
    if (blockShared && self != block.turn) return; // the block's turn texel writes this one
    uint blockTexels = blockShared ? block.surfaces : 0u;
    vec4 history = imageLoad(gImagesRgba16f[rt.shadelTermsWrite], atlas);
    float count = reset ? 0.0 : history.w;
    // Converged: the texel is reused as it is until its inputs change (traced once
    // per shadel, then reused; a reset starts it again).
    if (count >= float(rt.historyRays)) return;
    // Seen this frame? (A shared block is tested at its centre: it stands for all four texels.)
    vec2 seenAt = blockShared ? vec2((texel & ~1u) + 1u) / vec2(o.size) : shadelCenterUv(texel, o.size);
    if (!shadelMarkedAt(s, tile.object, seenAt)) {
        if (count == 0.0) { // never read as it is: empty until traced
            storeTerms(rt, o, texel, blockTexels, vec4(1.0, 1.0, 0.0, 0.0), vec4(0.0));
            if (rt.spotShadowCount != 0u) storeSpots(rt, o, texel, blockTexels, uvec4(0xFFFFFFFFu));
        }
        return;
    }
    uint tri = texelTriangle(s, o, texel);
    if (tri == 0xFFFFu) { // no surface here (outside every chart and its gutter): never read
        imageStore(gImagesRgba16f[rt.shadelTermsWrite], atlas, vec4(1.0, 1.0, 0.0, 0.0));
        imageStore(gImagesRgba16f[rt.shadelIndirectWrite], atlas, vec4(0.0));
        if (rt.spotShadowCount != 0u) imageStore(gImagesRgba32ui[rt.shadelSpotWrite], atlas, uvec4(0xFFFFFFFFu));
        return;
    }
    GpuInstance inst = InstanceBuffer(f.instances).i[tile.object];
    GpuMesh mesh = MeshBuffer(f.meshes).m[inst.mesh];
    IndexBuffer indices = IndexBuffer(f.indices);
    uint i0 = indices.i[mesh.firstIndex + tri * 3u] + uint(mesh.vertexOffset);
    uint i1 = indices.i[mesh.firstIndex + tri * 3u + 1u] + uint(mesh.vertexOffset);
    uint i2 = indices.i[mesh.firstIndex + tri * 3u + 2u] + uint(mesh.vertexOffset);
    Vec2Buffer uvs = Vec2Buffer(s.shadelUvs);
    vec3 bary = shadelBarycentrics(shadelCenterUv(texel, o.size), uvs.v[i0], uvs.v[i1], uvs.v[i2]);
    // At coarse MIPs a texel's centre can lie far outside the triangle its ID map names (the
    // gutter flood, or a triangle smaller than the texel): the point is pulled onto the triangle
    // so that rays leave the surface, not the inside of the object.
    bary = max(bary, vec3(0.0));
    bary /= max(bary.x + bary.y + bary.z, 1e-6);
    VertexBuffer vb = VertexBuffer(f.vertices);
    GpuVertex v0 = vb.v[i0], v1 = vb.v[i1], v2 = vb.v[i2];
    vec3 p = (inst.model * vec4(shadelInterpolate(bary, v0.position, v1.position, v2.position), 1.0)).xyz;
    vec3 n = normalize(mat3(inst.normalMatrix) * shadelInterpolate(bary, v0.normal, v1.normal, v2.normal));
    vec3 ng = normalize(mat3(inst.normalMatrix) * cross(v1.position - v0.position, v2.position - v0.position));
    if (dot(ng, n) < 0.0) ng = -ng;
    // Only what the camera can see is traced this frame: texels facing away (single-sided
    // materials) or outside the view frustum (with a margin for the filters' reach) wait until
    // they come into view; on a reset they are marked empty, so stale texels are never read.
    GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
    bool facing = (mat.flags & MATERIAL_DOUBLE_SIDED) != 0u || dot(ng, f.cameraPosition - p) > 0.0;
    float margin = 0.05 * length(f.cameraPosition - p);
    bool inView = true;
    for (int i = 0; i < 6; ++i) inView = inView && dot(f.frustumPlanes[i], vec4(p, 1.0)) >= -margin;
    if (!facing || !inView) {
        if (count == 0.0) {
            storeTerms(rt, o, texel, blockTexels, vec4(1.0, 1.0, 0.0, 0.0), vec4(0.0));
            if (rt.spotShadowCount != 0u) storeSpots(rt, o, texel, blockTexels, uvec4(0xFFFFFFFFu));
        }
        return;
    }

    vec4 indirectHistory = imageLoad(gImagesRgba16f[rt.shadelIndirectWrite], atlas);
    // A texel's first frame (new in view, or reset) traces no more than the others: while a
    // texel holds few rays, the read (useRayTracedShadelTerms) pools its neighbours' rays
    // instead (more rays on first frames were most of the path's cost under a moving camera).
    uint rays = rt.raysPerShadel;
    uint seed = rtHash(tile.object * 0x9e3779b9u ^ rtHash(uint(atlas.x) | uint(atlas.y) << 16));
    uint sampleBase = uint(count); // continue the sequence: no sample is drawn twice
    float sun = rt.shadows != 0u ? rtSunVisibility(f, rt, p, ng, seed, sampleBase) : 1.0;
    float ao = rt.ao != 0u ? rtAmbientOcclusion(f, rt, p, n, ng, seed, sampleBase, rays) : 1.0;
    vec3 indirect = rt.gi != 0u ? rtIndirectDiffuse(f, rt, p, n, ng, seed, sampleBase, rays) : vec3(0.0);
    // The running mean of every ray so far.
    float total = count + float(rays);
    float w = float(rays) / total;
    // The shading normal (octahedral) rides along: the read's wider filter pools only texels of
    // the same surface (at the cache's MIPs a chart's gutter is under a texel wide).
    vec2 octNormal = rtOctEncode(n);
    vec4 terms = vec4(mix(history.xy, vec2(sun, ao), w), octNormal.x, total);
    storeTerms(rt, o, texel, blockTexels, terms, vec4(mix(indirectHistory.rgb, indirect, w), octNormal.y));
    // Hard spot shadows are exact from the first frame (one ray to each light from a fixed
    // point): traced again only after a reset. Soft ones accumulate; 8 bits per spot: a running
    // mean below 1/16 per frame would round to no change.
    if (rt.spotShadowCount != 0u && (count == 0.0 || rt.shadowRays > 1u)) {
        uvec4 spots = rtSpotVisibilities(f, rt, p, ng, seed ^ 0x7a3c1u, sampleBase);
        uvec4 spotHistory = count == 0.0 ? spots : imageLoad(gImagesRgba32ui[rt.shadelSpotWrite], atlas);
        storeSpots(rt, o, texel, blockTexels,
                   rtMixSpotVisibilities(spotHistory, spots, max(w, 1.0 / 16.0), rt.spotShadowCount));
    }
}
