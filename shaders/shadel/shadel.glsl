// Decoupled shading: addressing in the virtual shadel sheet, shared by marking, shading and
// reconstruction so all three agree on which chunk a sample reads.
#ifndef SHADEL_SHADEL_GLSL
#define SHADEL_SHADEL_GLSL
#include "common/bindless.glsl"

layout(buffer_reference, scalar) buffer ShadelCountersRef { GpuShadelCounters c; };
layout(buffer_reference, scalar) readonly buffer ShadelRectBuffer { GpuShadelRect r[]; };
layout(buffer_reference, scalar) buffer ShadelWorkBuffer { GpuShadelWork w[]; };
layout(buffer_reference, scalar) buffer Uvec4Buffer { uvec4 v[]; };
layout(buffer_reference, scalar) buffer Uvec2Buffer { uvec2 v[]; };
layout(buffer_reference, scalar) readonly buffer Vec4Buffer { vec4 v[]; };

// Anisotropic footprint: a pixel's footprint in MIP-0 shadels is the parallelogram spanned by
// texelDx and texelDy: its length is the longer axis, its width the area over that length. A
// grazing footprint is read by `taps` bilinear samples spread along the long axis, from the MIP
// whose shadel is length / aniso, aniso = min(length / width, SHADEL_MAX_ANISO): the MIP follows
// both screen axes instead of blurring to the long one (at a bounded cost in shadels: about aniso
// times the isotropic count). aniso <= length / width keeps the chosen footprint >= the width, so
// the MIP is never finer than the footprint's narrow side and the CPU's per-object lower bound of
// the finest MIP (footprintLod and finestMipFromLod in coarse_visit.cpp, from the shortest span a
// pixel can have) stays a lower bound.
ShadelObjectRef shadelObject(ShadelFrame s, uint object) {
    return ShadelObjectRef(s.objects + uint64_t(object) * GPU_SHADEL_OBJECT_BYTES);
}

const float SHADEL_MAX_ANISO = 1.5;

struct ShadelAniso {
    float footprintSq; // (MIP-0 shadels a tap stands for)^2, the footprint >= the width
    vec2 step;         // MIP-0 shadels between neighbouring taps
    uint taps;
};

ShadelAniso shadelAniso(vec2 texelDx, vec2 texelDy) {
    float lx2 = dot(texelDx, texelDx), ly2 = dot(texelDy, texelDy);
    float len2 = max(max(lx2, ly2), 1e-30);
    float area = texelDx.x * texelDy.y - texelDx.y * texelDy.x; // = width * length
    ShadelAniso a;
    // length / clamp(length / width, 1, SHADEL_MAX_ANISO) = max(width, length / MAX) (width <=
    // length), squared: no square root nor division per axis (marking and reconstruction take
    // it per pixel).
    a.footprintSq = max(area * area / len2, len2 * (1.0 / (SHADEL_MAX_ANISO * SHADEL_MAX_ANISO)));
    // One tap: the MIP already follows the narrow side (up to SHADEL_MAX_ANISO). Measured on
    // lavapipe at 1280x720 (builtin:default, builtin:checker), a second tap along the long axis
    // cost 2-3x in marking and reconstruction and was 0.4-0.5 dB further from the 8x8 SSAA
    // checker reference; the tap loop stays for a higher anisotropy cap.
    a.taps = 1u;
    a.step = (lx2 >= ly2 ? texelDx : texelDy) / float(a.taps);
    return a;
}

// The shadel-UV of tap i of n, centred on uv.
vec2 shadelTapUv(uvec2 mip0Size, vec2 uv, ShadelAniso a, uint i) {
    return uv + a.step * (float(i) - 0.5 * float(a.taps - 1u)) / vec2(mip0Size);
}

// MIP selection: the same in marking and reconstruction (a custom MIP calculation, not the
// hardware's). `texel` is the position in MIP-0 shadels; derivatives are per pixel.
float shadelLod(vec2 texelDx, vec2 texelDy, float bias) {
    return 0.5 * log2(max(shadelAniso(texelDx, texelDy).footprintSq, 1e-16)) + bias;
}

uvec2 levelSize(ShadelObjectRef o, uint mip) { return max(o.v.mip0Size >> mip, uvec2(1u)); }

// The MIPs a sample reads and the weight of the second. Two MIPs are blended only inside a band
// around the middle of each LOD interval ("brilinear"): near integer LODs one
// level is read, so marking, storage and reconstruction all touch fewer chunks. Marking and
// reconstruction call this with the same inputs, so they always agree.
struct ShadelLevels {
    uint mip0;
    uint mip1;
    float blend; // weight of mip1
    bool two;    // read both levels
};

// texelDx/Dy: screen derivatives of the sample's MIP-0 shadel coordinate.
ShadelLevels shadelLevels(ShadelObjectRef o, vec2 texelDx, vec2 texelDy, float bias, float band) {
    // The object has rects only from firstMip on (the CPU's lower bound of what it can need).
    // The object's material shading rate (render/shadel/material_rate.h materialRateLod) on top
    // of the frame's bias. A textured material's (render/shadel/texture_rate.h) coarsens a sample
    // no further than a quarter texel (the level before o.v.textureLod); without textures
    // o.v.textureLod is SHADEL_TEXTURE_LOD_NONE and the bias applies in full.
    float lod = shadelLod(texelDx, texelDy, bias);
    float rateBias = min(o.v.rateBias, max(o.v.textureLod - 1.0 - lod, 0.0));
    // Both levels a sample can blend hold its textures at half a texel or finer: the band below
    // may close.
    float bandBias = lod < o.v.textureLod ? o.v.rateBias : 0.0;
    lod = max(lod, min(lod + rateBias, SHADEL_MATERIAL_RATE_MAX_LOD));
    lod = clamp(lod, float(o.v.firstMip), float(o.v.mipCount - 1u));
    ShadelLevels l;
    l.mip0 = uint(floor(lod));
    l.mip1 = min(l.mip0 + 1u, o.v.mipCount - 1u);
    float f = lod - float(l.mip0);
    // The band narrows with the object's material rate bias (0 to 1 MIP: MaterialRate::maxBias),
    // to one level at the full bias: the rate system biases only surfaces that show smooth
    // lighting alone or with textures both levels resolve, so neighbouring levels hold nearly the
    // same values there and a blend adds only the finer level's chunks. At 1280x720 against 4x4
    // SSAA forward, shadels per pixel and PSNR: builtin:default 0.746 -> 0.653, 28.971 -> 28.970
    // dB; builtin:many 0.595 -> 0.429, 38.745 -> 38.716 dB; 2CylinderEngine 1.589 -> 1.173,
    // 37.553 -> 37.537 dB.
    band *= 1.0 - clamp(bandBias, 0.0, 1.0);
    float t = band >= 1.0 ? f : clamp((f - 0.5 * (1.0 - band)) / max(band, 1e-6), 0.0, 1.0);
    if (t >= 1.0 && l.mip1 != l.mip0) { l.mip0 = l.mip1; t = 0.0; }
    l.blend = t;
    l.two = t > 0.0 && l.mip1 != l.mip0;
    return l;
}

// The 2x2 bilinear footprint at `mip` of the sample at shadel-UV `uv`: first texel + weights.
void bilinearFootprint(ShadelObjectRef o, uint mip, vec2 uv, out ivec2 texel0, out vec2 weight) {
    vec2 size = vec2(levelSize(o, mip));
    vec2 t = uv * size - 0.5;
    texel0 = ivec2(floor(t));
    weight = t - vec2(texel0);
}

// Origin of the level's window (the part of the level its rect holds), in level texels.
uvec2 windowOrigin(ShadelObjectRef o, uint mip) {
    uint w = o.v.window[mip];
    return uvec2(w & 0xFFFFu, w >> 16) * SHADEL_BLOCK;
}

// The level texel a tap reads: clamped to the level, so border taps never leave the object.
uvec2 levelTexel(ShadelObjectRef o, uint mip, ivec2 texel) {
    return uvec2(clamp(texel, ivec2(0), ivec2(levelSize(o, mip)) - 1));
}

// A sample whose wanted level's window lags by more than one level (a camera cut: last frame's
// marks were elsewhere) is shaded forward instead of read that much coarser: from two levels
// up, charts bleed into each other's shadels (bake.h: only levels <= log2(gutter) are clean)
// and the blur shows. The resolve shades it from its surface, as a miss (counted apart:
// window_forward_pixel_fraction). Marking still marks what it would have read (checking per
// tap cost the marking pass 2 ms at 1280x720; a cut frame's coarse chunks are few). One level
// up stays a read.
const uint SHADEL_MAX_WINDOW_FALLBACK = 1u;

bool windowFallbackTooDeep(ShadelLevels wanted, ShadelLevels fitted) {
    return fitted.mip0 > wanted.mip0 + SHADEL_MAX_WINDOW_FALLBACK;
}

// Sheet shadel coordinate of an object's level texel (clamped to the level; the level's window
// must hold it: fitLevelFootprints).
uvec2 sheetShadel(ShadelObjectRef o, uint mip, ivec2 texel) {
    return o.v.rect[mip].xy * SHADEL_BLOCK + levelTexel(o, mip, texel) - windowOrigin(o, mip);
}

// A sample's 2x2 bilinear footprint at one level, in the sheet: the first and last shadel (the
// last is the first + 0 or 1 on each axis: clamped at the level's edge) and the weights of the
// second column and row. Marking marks its chunks, reconstruction reads them.
struct LevelFootprint {
    uvec2 lo;
    uvec2 hi;
    vec2 weight;
};

// The footprint at one level and whether the level's window holds it (a coarse level's window
// is the level, so it always does), from one bilinear footprint.
bool heldLevelFootprint(ShadelObjectRef o, uint mip, vec2 uv, out LevelFootprint fp) {
    ivec2 t0;
    bilinearFootprint(o, mip, uv, t0, fp.weight);
    uvec2 lo = levelTexel(o, mip, t0), hi = levelTexel(o, mip, t0 + ivec2(1));
    uvec4 rect = o.v.rect[mip];
    uvec2 origin = windowOrigin(o, mip);
    fp.lo = rect.xy * SHADEL_BLOCK + lo - origin; // sheetShadel
    fp.hi = rect.xy * SHADEL_BLOCK + hi - origin;
    return all(greaterThanEqual(lo, origin)) && all(lessThan(hi, origin + rect.zw * SHADEL_BLOCK));
}

// Whether the level's window holds the whole 2x2 footprint at `uv`.
bool windowHolds(ShadelObjectRef o, uint mip, vec2 uv) {
    LevelFootprint fp;
    return heldLevelFootprint(o, mip, uv, fp);
}

// Level windows: a sample whose footprint a level's window does not hold reads the next
// coarser level instead (the coarsest is always whole, so one is found); a second level of a
// blend that does not hold it is dropped. Marking and reconstruction both call this, so they
// agree. Returns the levels that were wanted but not held (bit per MIP): marking records them
// so next frame's windows grow there. fp0/fp1: the fitted levels' footprints (fp1 = fp0 unless
// two levels are read), each level's computed once for its window test and its taps (apart,
// the test and the footprints cost marking ~5 ms of 26: builtin:default 1280x720, lavapipe).
uint fitLevelFootprints(ShadelObjectRef o, vec2 uv, inout ShadelLevels l, out LevelFootprint fp0,
                        out LevelFootprint fp1) {
    uint unheld = 0u;
    while (!heldLevelFootprint(o, l.mip0, uv, fp0) && l.mip0 + 1u < o.v.mipCount) {
        unheld |= 1u << l.mip0;
        l.mip0++;
        l.mip1 = l.mip0;
        l.two = false;
        l.blend = 0.0;
    }
    fp1 = fp0;
    if (l.two && !heldLevelFootprint(o, l.mip1, uv, fp1)) {
        unheld |= 1u << l.mip1;
        l.two = false;
        l.blend = 0.0;
        fp1 = fp0;
    }
    return unheld;
}

// The fitted levels alone (--inspect).
uint fitLevelsToWindows(ShadelObjectRef o, vec2 uv, inout ShadelLevels l) {
    LevelFootprint fp0, fp1;
    return fitLevelFootprints(o, uv, l, fp0, fp1);
}

// The level texel of a sheet shadel of the object's level `mip` (the inverse of sheetShadel).
uvec2 levelShadel(ShadelObjectRef o, uint mip, uvec2 sheet) {
    return sheet - o.v.rect[mip].xy * SHADEL_BLOCK + windowOrigin(o, mip);
}

uint blockIndex(ShadelFrame s, uvec2 sheetShadel) {
    uvec2 b = sheetShadel / SHADEL_BLOCK;
    return b.y * s.sheetBlocks + b.x;
}

// Preserved layers: the block of last frame's sheet that held this frame's sheet block `block`
// of the object's level `mip`, or SHADEL_INVALID where last frame's window did not hold it. A
// level whose window moved was placed anew (GpuShadelObject::prevRect*); windows and rects are
// whole blocks, so a block maps to one block with the same chunk bits.
uint prevBlockIndex(ShadelFrame s, ShadelObjectRef o, uint mip, uint block) {
    uvec2 sheetBlock = uvec2(block % s.sheetBlocks, block / s.sheetBlocks);
    uvec2 levelBlock = sheetBlock - o.v.rect[mip].xy + windowOrigin(o, mip) / SHADEL_BLOCK;
    uint w = o.v.prevWindow[mip], origin = o.v.prevRectOrigin[mip], size = o.v.prevRectSize[mip];
    uvec2 prevWindow = uvec2(w & 0xFFFFu, w >> 16);
    uvec2 prevSize = uvec2(size & 0xFFFFu, size >> 16);
    if (any(lessThan(levelBlock, prevWindow)) || any(greaterThanEqual(levelBlock, prevWindow + prevSize)))
        return SHADEL_INVALID;
    uvec2 prev = uvec2(origin & 0xFFFFu, origin >> 16) + levelBlock - prevWindow;
    return prev.y * s.sheetBlocks + prev.x;
}

uint chunkBit(uvec2 sheetShadel) {
    uvec2 c = (sheetShadel / SHADEL_CHUNK) % (SHADEL_BLOCK / SHADEL_CHUNK);
    return c.y * 8u + c.x;
}

// Storage slot of a marked chunk: the block's base + the marked chunks before it (popcount).
uint chunkSlot(uint64_t mask, uint base, uint bit) {
    uint64_t below = bit == 0u ? 0ul : (mask & ((1ul << bit) - 1ul));
    return base + bitCount(uint(below)) + bitCount(uint(below >> 32));
}

// Preserved layers: a carried-over chunk is still reshaded once per refresh period
// (--reuse-refresh), each chunk at its own phase, so nothing goes stale for long (view-dependent
// terms are reshaded sooner when the view turns: chunkViewTurned).
bool shadelRefreshDue(ShadelFrame s, uint chunk) {
    return (((chunk * 2654435761u) >> 20) + s.frameNumber) % max(s.refreshPeriod, 1u) == 0u;
}

// The shading class of an object (its chunks' list, SHADE_QUEUE_* - 1).
uint shadeClassOf(ShadelObjectRef o) {
    if ((o.v.flags & SHADEL_OBJECT_SUPERSAMPLED) != 0u) return SHADE_QUEUE_SUPERSAMPLED - 1u;
    if ((o.v.flags & SHADEL_OBJECT_TEXTURED_MATERIAL) != 0u) return SHADE_QUEUE_TEXTURED - 1u;
    if ((o.v.flags & SHADEL_OBJECT_FEATURED_MATERIAL) != 0u) return SHADE_QUEUE_FEATURED - 1u;
    return SHADE_QUEUE_PLAIN - 1u;
}

// Octahedral mapping of a unit vector to [-1, 1]^2 and back (chunk view directions).
vec2 shadelOctEncode(vec3 n) {
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    vec2 signs = vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    return n.z >= 0.0 ? n.xy : (1.0 - abs(n.yx)) * signs;
}
vec3 shadelOctDecode(vec2 e) {
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    float t = max(-n.z, 0.0);
    n.xy += vec2(n.x >= 0.0 ? -t : t, n.y >= 0.0 ? -t : t);
    return normalize(n);
}

// Preserved layers: what a chunk's record holds (ShadelFrame::chunkViews) when it was shaded
// seen from `camera`, `centre` a point of its surface (chunkSurfacePoint); none when no shadel
// of it is covered.
uvec4 chunkViewRecord(bool seen, vec3 centre, vec3 camera) {
    if (!seen) return uvec4(SHADEL_CHUNK_VIEW_NONE);
    vec3 toCamera = camera - centre;
    float len = length(toCamera);
    vec3 dir = len > 0.0 ? toCamera / len : vec3(0.0, 0.0, 1.0);
    return uvec4(floatBitsToUint(centre), packSnorm2x16(shadelOctEncode(dir)));
}

// Whether the view of a carried-over chunk turned, since it was shaded, past what its object's
// specular tolerates (GpuShadelObject::viewDriftCos): the angle between the directions from
// the chunk's centre to the camera then and now. Chunks far from the camera turn slowly and are
// carried over long; a chunk near a moving camera is reshaded as often as its lobe needs.
bool chunkViewTurned(ShadelFrame s, ShadelObjectRef o, uint prevSlot, vec3 camera) {
    uvec4 record = Uvec4Buffer(s.prevChunkViews).v[prevSlot];
    if (record.x == SHADEL_CHUNK_VIEW_NONE) return false; // nothing in it is ever seen
    vec3 centre = uintBitsToFloat(record.xyz);
    vec3 then = shadelOctDecode(unpackSnorm2x16(record.w));
    vec3 toCamera = camera - centre;
    float len = length(toCamera);
    if (len <= 0.0) return true;
    return dot(then, toCamera / len) < o.v.viewDriftCos; // cosines: no acos per chunk
}

// The shade storage (ShadelFrame::layers): one buffer per layer, chunk-linear, so a chunk's
// shadels are contiguous (a carried-over chunk is one block copy) and a tap is a buffer load (a
// bindless texelFetch costs far more on CPU devices). Callers go through the load/store pairs
// below and never pack by hand.
layout(buffer_reference, scalar, buffer_reference_align = 8) buffer ShadeRadianceLayer { uvec2 v[]; };
layout(buffer_reference, scalar, buffer_reference_align = 4) buffer ShadeMaterialLayer { uint v[]; };

// Element of shadel `inChunk` (0..7 each) of the chunk in storage slot `slot`.
uint storageIndex(uint slot, uvec2 inChunk) {
    return slot * (SHADEL_CHUNK * SHADEL_CHUNK) + inChunk.y * SHADEL_CHUNK + inChunk.x;
}

// Radiance: RGBA16F as two packHalf2x16 words.
vec4 loadRadiance(uint64_t layer, uint index) {
    uvec2 v = ShadeRadianceLayer(layer).v[index];
    return vec4(unpackHalf2x16(v.x), unpackHalf2x16(v.y));
}
void storeRadiance(uint64_t layer, uint index, vec4 radiance) {
    ShadeRadianceLayer(layer).v[index] = uvec2(packHalf2x16(radiance.rg), packHalf2x16(radiance.ba));
}

// Material: base colour + roughness, RGBA8 unorm (packUnorm4x8 clamps to [0, 1]).
vec4 loadMaterial(uint64_t layer, uint index) {
    return unpackUnorm4x8(ShadeMaterialLayer(layer).v[index]);
}
void storeMaterial(uint64_t layer, uint index, vec4 material) {
    ShadeMaterialLayer(layer).v[index] = packUnorm4x8(material);
}

// Either layer by its index (SHADEL_LAYER_*), as the reconstruction's debug views choose it.
vec4 loadLayer(ShadelFrame s, uint layer, uint index) {
    return layer == SHADEL_LAYER_MATERIAL ? loadMaterial(s.layers[SHADEL_LAYER_MATERIAL], index)
                                          : loadRadiance(s.layers[SHADEL_LAYER_RADIANCE], index);
}

// Carry-over (preserved layers): row `row` (0..7) of the chunk last frame stored in slot
// `fromSlot`, every layer, into slot `toSlot`, the packed words as they are. A chunk row is
// contiguous in each layer (storageIndex): radiance 8 shadels x uvec2 = 4 uvec4s, material
// 8 x uint = 2 uvec4s.
void carryChunkRow(ShadelFrame s, uint fromSlot, uint toSlot, uint row) {
    const uint radianceRow = SHADEL_CHUNK / 2u, materialRow = SHADEL_CHUNK / 4u; // uvec4s
    uint from = fromSlot * SHADEL_CHUNK + row, to = toSlot * SHADEL_CHUNK + row;
    Uvec4Buffer radianceIn = Uvec4Buffer(s.prevLayers[SHADEL_LAYER_RADIANCE]);
    Uvec4Buffer radianceOut = Uvec4Buffer(s.layers[SHADEL_LAYER_RADIANCE]);
    for (uint i = 0u; i < radianceRow; ++i)
        radianceOut.v[to * radianceRow + i] = radianceIn.v[from * radianceRow + i];
    Uvec4Buffer materialIn = Uvec4Buffer(s.prevLayers[SHADEL_LAYER_MATERIAL]);
    Uvec4Buffer materialOut = Uvec4Buffer(s.layers[SHADEL_LAYER_MATERIAL]);
    for (uint i = 0u; i < materialRow; ++i)
        materialOut.v[to * materialRow + i] = materialIn.v[from * materialRow + i];
}

// What travels with a carried chunk besides its shadels, once per chunk: where it was seen from
// when shaded (chunkViews), and the count.
void carryChunkRecord(ShadelFrame s, uint fromSlot, uint toSlot) {
    Uvec4Buffer(s.chunkViews).v[toSlot] = Uvec4Buffer(s.prevChunkViews).v[fromSlot];
    atomicAdd(ShadelCountersRef(s.counters).c.chunksReused, 1u);
    if (s.chunkReasons != 0ul) UintBuffer(s.chunkReasons).v[toSlot] = SHADEL_CHUNK_CARRIED;
}
#endif
