// The engine's part of a material program stage before the author's code: the shadel this
// invocation shades (one 8x8 workgroup per chunk of the program's list, as shadel/shade.comp),
// the surface point rebuilt from the mesh, the stage's layer access and the scene's lighting.
// The author's stage reads `surface` and writes layers in its main(); program_main.glsl runs it.
#include "shadel/shadel.glsl"
#include "shadel/shade_chunk.glsl"
#include "common/dispatch_2d.h"
#include "common/lighting.glsl"
#include "common/tone_curve.glsl"
#include "materials/program_types.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t header;  // the program lists (program_types.h): counts and dispatch arguments
    uint64_t queues;  // their entries
    uint program;     // this program's index in them
    uint capacity;    // entries per list
} pc;

// The surface point a shadel stands for: the mesh interpolated at the shadel's centre, in world
// space, and its footprint (how far the next shadel right and down is, in UV and in world).
struct Surface {
    vec3 position;        // world
    vec3 normal;          // world, unit, interpolated
    vec4 tangent;         // world xyz, handedness in w
    vec3 geometricNormal; // world, unit: the triangle's
    vec2 uv;              // TEXCOORD_0
    vec2 uvDx, uvDy;      // uv of the next shadel right / down, minus uv
    vec3 positionDx, positionDy; // the same for the world position
    vec2 uv1;             // TEXCOORD_1
    bool frontFacing;     // its normal faces the camera
    uvec2 shadel;         // in the object's MIP level
    uvec2 levelSize;      // shadels of that level
    uint object;          // instance index
};

Surface surface;
FrameConstants gMaterialFrame;
ShadelFrame gMaterialShadel;
GpuMaterial material; // the object's glTF material (factors, textures), as it is this frame
uint gMaterialIndex; // the shadel's element in the shade storage
GpuShadelWork gMaterialWork; // its chunk

// This shadel's value in a layer (what an earlier stage, or carry-over, wrote there this frame).
vec4 readLayer(uint layer) {
    return loadLayer(gMaterialShadel, layer, gMaterialIndex);
}
void writeLayer(uint layer, vec4 value) {
    if (layer == SHADEL_LAYER_MATERIAL)
        storeMaterial(gMaterialShadel.layers[SHADEL_LAYER_MATERIAL], gMaterialIndex, value);
    else
        storeRadiance(gMaterialShadel.layers[SHADEL_LAYER_RADIANCE], gMaterialIndex, value);
}

// Preserved layers: last frame's value of this very shadel in a layer (what the program's last
// stage, or carry-over, left there), and true, when last frame stored it: the object was
// decoupled at this level last frame, its level was placed before this frame (or moved with its
// shadels), nothing reposed it or changed everything, and the chunk was in last frame's storage.
// Otherwise false, never a neighbour's or another surface's value. Needs --reuse on.
bool prevSample(uint layer, out vec4 value) {
    value = vec4(0.0);
    ShadelFrame s = gMaterialShadel;
    ShadelObjectRef o = shadelObject(s, gMaterialWork.object);
    if (s.reuse == 0u || ((o.v.reuseLevels >> gMaterialWork.mip) & 1u) == 0u) return false;
    uvec2 sheet = uvec2(gMaterialWork.chunk & 0xFFFFu, gMaterialWork.chunk >> 16) * SHADEL_CHUNK;
    uint block = prevBlockIndex(s, o, gMaterialWork.mip, blockIndex(s, sheet));
    if (block == SHADEL_INVALID) return false;
    uint bit = chunkBit(sheet);
    uint64_t prevMask = Uint64Buffer(s.prevOccupancy).v[block];
    uint prevBase = UintBuffer(s.prevOffsetMap).v[block];
    if ((prevMask & (1ul << bit)) == 0ul || prevBase == SHADEL_INVALID) return false;
    uint index = storageIndex(chunkSlot(prevMask, prevBase, bit), gl_LocalInvocationID.xy);
    value = layer == SHADEL_LAYER_MATERIAL ? loadMaterial(s.prevLayers[SHADEL_LAYER_MATERIAL], index)
                                           : loadRadiance(s.prevLayers[SHADEL_LAYER_RADIANCE], index);
    return true;
}

// A number in [0, 1) for this shadel, the same every frame (a different one per `salt`).
float shadelRandomFixed(uint salt) {
    uvec3 v = uvec3(surface.shadel, surface.object * 7919u + salt * 131u);
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.z; v.y += v.z * v.x; v.z += v.x * v.y;
    v ^= v >> 16u;
    v.x += v.y * v.z; v.y += v.z * v.x; v.z += v.x * v.y;
    return float(v.x >> 8) / 16777216.0;
}

// A number in [0, 1) for this shadel and frame (a different one each frame and `salt`).
float shadelRandom(uint salt) {
    uvec3 v = uvec3(surface.shadel, surface.object * 7919u + gMaterialFrame.frameIndex * 131u + salt);
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.z; v.y += v.z * v.x; v.z += v.x * v.y;
    v ^= v >> 16u;
    v.x += v.y * v.z; v.y += v.z * v.x; v.z += v.x * v.y;
    return float(v.x >> 8) / 16777216.0;
}

// Radiance to the display's [0, 1] (exposure and the filmic curve) and back: stages that
// average samples average what the viewer sees, as the supersampled reference averages pixels
// (an average in linear light of a bright/dark pattern displays too bright).
vec3 toDisplay(vec3 radiance) {
    return acesFit(max(radiance, vec3(0.0)) * max(gMaterialFrame.exposure, 1e-6));
}
vec3 fromDisplay(vec3 display) {
    return acesFitInverse(display) / max(gMaterialFrame.exposure, 1e-6);
}

// The scene's lighting (sun, lights, environment, GI) of a metal/rough surface at the shadel,
// seen from the camera: what the glTF PBR program computes for a material without textures.
vec3 lightSurface(vec3 baseColor, float metallic, float roughness, vec3 normal) {
    MaterialSample m;
    m.baseColor = baseColor;
    m.alpha = 1.0;
    m.normal = normalize(normal);
    m.metallic = clamp(metallic, 0.0, 1.0);
    m.roughness = clamp(roughness, 0.0, 1.0);
    m.occlusion = 1.0;
    m.ambientOcclusion = 1.0;
    m.emissive = vec3(0.0);
    m.specularF0 = vec3(0.04);
    m.specularF90 = 1.0;
    m.clearcoat = 0.0;
    m.clearcoatRoughness = 0.0;
    m.clearcoatNormal = m.normal;
    m.sheenColor = vec3(0.0);
    m.sheenRoughness = 0.07;
    m.unlit = false;
    m.sheenAlbedoScale = 1.0;
    return shadeSurface(gMaterialFrame, m, surface.position, surface.geometricNormal);
}

// Parameters and layer names (LAYER_RADIANCE, ...) follow, generated from the .shmat.
