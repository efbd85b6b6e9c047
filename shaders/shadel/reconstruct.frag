#version 460
// Reconstruction (seed: "Scene Render"): the decoupled objects drawn again, reading their
// shaded samples: offset map + popcount find each chunk in storage, bilinear across chunk
// edges and trilinear across MIPs. A tap whose chunk was never marked is a miss (counted; must
// be 0); a tap whose chunk overflowed storage is counted too. Either way the pixel is shaded
// forward with the same material code, so the image never shows a hole.
#include "shadel/shadel.glsl"
#include "common/lighting.glsl"

layout(early_fragment_tests) in;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint shadowView;
} pc;

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inTangent;
layout(location = 3) in vec2 inUv;
layout(location = 4) flat in uint inInstance;
layout(location = 5) in vec2 inShadelUv;

layout(location = 0) out vec4 outColor;

vec3 sampleLevel(ShadelFrame s, GpuShadelObject o, uint mip, vec2 uv, uint layerSlot,
                 inout uint missing, inout uint overflowed, out uint64_t firstMask) {
    ivec2 t0;
    vec2 w;
    bilinearFootprint(o, mip, uv, t0, w);
    vec3 sum = vec3(0.0);
    firstMask = 0ul;
    // The four taps usually share one block: look its mask and base up once.
    uint cachedBlock = SHADEL_INVALID;
    uint64_t mask = 0ul;
    uint base = SHADEL_INVALID;
    for (int i = 0; i < 4; ++i) {
        ivec2 offset = ivec2(i & 1, i >> 1);
        uvec2 sheet = sheetShadel(o, mip, t0 + offset);
        uint block = blockIndex(s, sheet);
        if (block != cachedBlock) {
            cachedBlock = block;
            mask = Uint64Buffer(s.occupancy).v[block];
            base = UintBuffer(s.offsetMap).v[block];
        }
        if (i == 0) firstMask = mask;
        uint bit = chunkBit(sheet);
        if ((mask & (1ul << bit)) == 0ul) { missing++; continue; }
        if (base == SHADEL_INVALID) { overflowed++; continue; }
        uint slot = chunkSlot(mask, base, bit);
        vec3 c = fetchTextureUniform(layerSlot, storageTexel(s, slot, sheet % SHADEL_CHUNK), 0).rgb;
        float weight = (offset.x == 1 ? w.x : 1.0 - w.x) * (offset.y == 1 ? w.y : 1.0 - w.y);
        sum += c * weight;
    }
    return sum;
}

vec3 forwardShade(FrameConstants f) {
    GpuInstance inst = InstanceBuffer(f.instances).i[inInstance];
    GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
    SurfaceInput si;
    si.position = inPosition;
    si.normal = normalize(inNormal);
    si.tangent = inTangent;
    si.uv = inUv;
    si.uvDx = dFdx(inUv);
    si.uvDy = dFdy(inUv);
    si.frontFacing = gl_FrontFacing;
    MaterialSample m = evaluateMaterial(mat, si);
    return shadeSurface(f, m, inPosition, si.normal);
}

vec3 heat(float t) {
    t = clamp(t, 0.0, 1.0);
    return clamp(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0), 1.5 - abs(4.0 * t - 1.0)), 0.0, 1.0);
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    GpuShadelObject o = ShadelObjectBuffer(s.objects).o[inInstance];
    vec2 texel = inShadelUv * vec2(o.mip0Size);
    ShadelLevels l = shadelLevels(o, dFdx(texel), dFdy(texel), s.shadingBias, s.trilinearBand);
    ShadelAniso a = shadelAniso(dFdx(texel), dFdy(texel));
    uint m0 = l.mip0;
    float lod = float(l.mip0) + l.blend;
    uint missing = 0u, overflowed = 0u;
    uint64_t mask0 = 0ul, mask1, tapMask;
    // --visualize layer:material reads the material layer where the radiance layer is read.
    uint layer = f.visualize == VISUALIZE_LAYER_MATERIAL ? s.layerReadSlot[SHADEL_LAYER_MATERIAL]
                                                         : s.storageReadSlot;
    vec3 color = vec3(0.0);
    for (uint i = 0u; i < a.taps; ++i) { // the same taps marking marked
        vec2 uv = shadelTapUv(o.mip0Size, inShadelUv, a, i);
        vec3 c = sampleLevel(s, o, l.mip0, uv, layer, missing, overflowed, tapMask);
        if (i == 0u) mask0 = tapMask;
        if (l.two) c = mix(c, sampleLevel(s, o, l.mip1, uv, layer, missing, overflowed, mask1), l.blend);
        color += c;
    }
    color /= float(a.taps);

    ShadelCountersRef counters = ShadelCountersRef(s.counters);
    // Magnification: the MIP-0 shadel is larger than the pixel along the longer screen axis.
    // Counted on one pixel of every 2x2 (a fraction needs no more, and atomics cost).
    if (all(equal(ivec2(gl_FragCoord.xy) & 1, ivec2(0)))) {
        vec2 dx = dFdx(texel), dy = dFdy(texel);
        if (max(dot(dx, dx), dot(dy, dy)) < 1.0) atomicAdd(counters.c.magnifiedPixels, 1u);
        atomicAdd(counters.c.reconstructedPixels, 1u);
    }
    if (missing != 0u) atomicAdd(counters.c.reconstructionMisses, 1u);
    if (overflowed != 0u) atomicAdd(counters.c.overflowSamples, 1u);
    if (missing + overflowed != 0u) color = forwardShade(f);

    if (f.visualize == VISUALIZE_MARKING) {
        // Seed colours: green = block with any chunk marked, blue = block fully marked.
        vec3 tint = mask0 == ~0ul ? vec3(0.1, 0.2, 1.0) : vec3(0.1, 1.0, 0.2);
        color = mix(color, tint, 0.5);
    } else if (f.visualize == VISUALIZE_MIPS) {
        color = heat(lod / 7.0);
    } else if (f.visualize == VISUALIZE_CHUNKS) {
        vec2 level = inShadelUv * vec2(levelSize(o, m0)) / float(SHADEL_CHUNK);
        vec2 edge = abs(fract(level) - 0.5);
        vec2 width = fwidth(level) * 1.0;
        float line = float(any(greaterThan(edge, 0.5 - width)));
        color = mix(color, vec3(1.0, 0.9, 0.1), line);
    }
#ifdef SHADEL_DEBUG_SHADERS
    const bool showMisses = true; // debug builds: a miss is never hidden by the fallback
#else
    bool showMisses = f.visualize != VISUALIZE_NONE;
#endif
    if (showMisses && missing != 0u) color = vec3(1.0, 0.0, 1.0);
    outColor = vec4(color, 1.0);
}
