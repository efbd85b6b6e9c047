// GPU data layouts shared by C++ and GLSL (scalar block layout on both sides).
// C++ includes this inside namespace shadel::gpu with glm types; GLSL includes it directly.
#ifndef SHADEL_SHARED_TYPES_H
#define SHADEL_SHARED_TYPES_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace shadel::gpu {
using glm::ivec2;
using glm::mat4;
using glm::uvec2;
using glm::uvec4;
using glm::vec2;
using glm::vec3;
using glm::vec4;
using uint = uint32_t;
#endif

// Material flags.
#define MATERIAL_ALPHA_MASK 1u
#define MATERIAL_ALPHA_BLEND 2u
#define MATERIAL_DOUBLE_SIDED 4u
#define MATERIAL_UNLIT 8u

#define PROCEDURAL_NONE 0u
#define PROCEDURAL_TEXEL_CHECKER 1u
#define PROCEDURAL_BRICKS 2u

#define LIGHT_DIRECTIONAL 0u
#define LIGHT_POINT 1u
#define LIGHT_SPOT 2u

#define NO_TEXTURE 0xFFFFFFFFu

// Draw lists written by the instance culling pass.
#define DRAW_LIST_OPAQUE 0u    // forward-shaded opaque and alpha-masked instances
#define DRAW_LIST_BLEND 1u     // forward-shaded blended instances
#define DRAW_LIST_DECOUPLED 2u // opaque instances shaded in shadel space this frame
// Blended instances shaded in shadel space this frame (reconstructed into the OIT targets).
#define DRAW_LIST_DECOUPLED_BLEND 3u
#define DRAW_LIST_COUNT 4u

// Debug views (--visualize).
#define VISUALIZE_NONE 0u
#define VISUALIZE_MARKING 1u
#define VISUALIZE_MIPS 2u
#define VISUALIZE_CHUNKS 3u
#define VISUALIZE_SHEET 4u
#define VISUALIZE_LAYER_MATERIAL 5u // --visualize layer:material

// One vertex of the unified geometry buffer (matches shadel::Vertex).
struct GpuVertex {
    vec3 position;
    vec3 normal;
    vec4 tangent;
    vec2 uv0;
};

struct GpuMesh {
    uint firstIndex; // into the unified index buffer
    uint indexCount;
    int vertexOffset; // into the unified vertex buffer
    uint shadelMesh;  // index into GpuShadelMesh, 0xFFFFFFFF when the mesh is forward-only
    vec3 boundsMin;   // object space
    float pad0;
    vec3 boundsMax;
    float pad1;
};

struct GpuInstance {
    mat4 model;
    mat4 normalMatrix; // inverse transpose of model (upper 3x3 used)
    vec3 worldMin;
    uint mesh;
    vec3 worldMax;
    uint material;
};

struct GpuMaterial {
    vec4 baseColorFactor;
    vec3 emissiveFactor;
    float metallicFactor;
    float roughnessFactor;
    float normalScale;
    float occlusionStrength;
    float alphaCutoff;
    uint baseColorTexture; // bindless slots, NO_TEXTURE when absent
    uint metallicRoughnessTexture;
    uint normalTexture;
    uint emissiveTexture;
    uint occlusionTexture;
    uint flags;
    uint procedural;
    float proceduralScale;
    // Transparent materials: 0 = alpha-blended, 1 = additive (fire, glows), in between a mix;
    // weighted blended OIT composites both without sorting (render/oit).
    float additiveness;
};

struct GpuLight {
    vec3 position;
    uint type;
    vec3 direction;   // the way light travels
    float range;      // 0 = infinite
    vec3 color;       // colour * intensity
    float spotScale;  // 1 / max(cos(inner) - cos(outer), 1e-4)
    float spotOffset; // -cos(outer) * spotScale
    float pad0;
    float pad1;
    float pad2;
};

struct DrawIndexedCommand { // VkDrawIndexedIndirectCommand
    uint indexCount;
    uint instanceCount;
    uint firstIndex;
    int vertexOffset;
    uint firstInstance;
};

struct FrameConstants {
    mat4 view;
    mat4 proj;
    mat4 viewProj;
    mat4 invViewProj;
    mat4 sunViewProj;
    vec4 frustumPlanes[6]; // camera, world space, inside when dot(p, (x,1)) >= 0
    vec4 shadowPlanes[6];  // sun shadow volume
    vec3 cameraPosition;
    float exposure;
    vec3 sunDirection;  // the way sunlight travels
    uint sunShadowSlot; // bindless slot of the sun shadow map, NO_TEXTURE when off
    vec3 sunColor;
    float shadowTexelSize;
    vec3 skyColor;
    uint lightCount;
    vec3 ambientColor;
    uint instanceCount;
    vec2 viewportSize;
    vec2 invViewportSize;
    uint frameIndex;
    uint visualize;
    float shadingBias; // fractional MIP bias of the decoupled path
    uint inspectPixel; // --inspect: x | y << 16 at the internal resolution, or INSPECT_OFF
    uint64_t vertices;  // GpuVertex[]
    uint64_t indices;   // uint[]
    uint64_t meshes;    // GpuMesh[]
    uint64_t instances; // GpuInstance[]
    uint64_t materials; // GpuMaterial[]
    uint64_t lights;    // GpuLight[]
    uint64_t messages;  // ShaderMessages (shader asserts)
    uint64_t shadel;    // ShadelFrame (decoupled path), 0 when forward
};

// Shader -> CPU message channel (shader asserts and prints). Written with atomics, read after the frame.
#define SHADER_MESSAGE_CAPACITY 256u
struct ShaderMessage {
    uint assertId;
    uint shaderId;
    uint line;
    uint format; // prints (assertId has SHADER_PRINT_BIT): value type | count << 4
    uvec4 values;
};

// ---- Decoupled shading (render/shadel) ----------------------------------------------------
#define SHADEL_MAX_MIPS 10u
#define SHADEL_COUNTERS 16u // hashed allocation counters (seed: N parallel allocations)
#define SHADEL_BLOCK 64u    // shadels per block side (8 x 8 chunks)
#define SHADEL_CHUNK 8u     // shadels per chunk side
#define SHADEL_INVALID 0xFFFFFFFFu
#define SHADEL_OBJECT_DECOUPLED 1u // allocated in the sheet this frame: drawn decoupled
// Its bounds meet a light that changed this frame: carried-over chunks check their shadels.
#define SHADEL_OBJECT_NEAR_CHANGED_LIGHT 2u
#define SHADEL_MAX_CHANGED_LIGHTS 256u
// Material layers of the shade storage (seed: "layers of different bit depths"): every layer
// shares the slot allocation; each has its own format.
#define SHADEL_LAYER_RADIANCE 0u // lit colour, RGBA16F
#define SHADEL_LAYER_MATERIAL 1u // base colour + roughness, RGBA8 (for GI injection, debugging)
#define SHADEL_LAYERS 2u

// Per instance: where its shadel space lives in the virtual sheet at each MIP.
struct GpuShadelObject {
    uvec2 mip0Size; // MIP-0 shadel rect (BakedMesh::width/height)
    uint mipCount;
    uint flags;
    uint firstMip; // finest MIP with a rect this frame (the CPU's estimate of what it can need)
    // Bit k: MIP k's rect and every shading input of the object (transform, material, lights in
    // range) are unchanged since last frame, so last frame's shadels there may be carried over.
    uint reuseLevels;
    // Frames a carried-over chunk may go unshaded: fewer where the camera's motion, seen from
    // the object, turns the view direction faster (view-dependent terms drift).
    uint refreshPeriod;
    uint idMapOffset[SHADEL_MAX_MIPS]; // in 16-bit units into ShadelFrame::idMaps
    uvec4 rect[SHADEL_MAX_MIPS];       // x, y, w, h in blocks of the virtual sheet
};

// One rectangle of the sheet in use this frame (the clear and allocation passes walk these).
struct GpuShadelRect {
    uvec4 rect; // x, y, w, h in blocks
    uint object;
    uint mip;
    uint firstBlock; // prefix sum of w*h over the rect list
    uint pad;
};

// One chunk of shading work: {chunk, storage slot, object, MIP} as in the seed.
struct GpuShadelWork {
    uint chunk; // sheet chunk coordinate, x | y << 16
    uint slot;  // storage chunk slot
    uint object;
    uint mip;
};

struct GpuShadelCounters {
    // Chunks requested through each hashed counter. The counters only spread the atomics: once
    // every block has its place within its counter, the sections are laid end to end
    // (sectionBase), so storage is shared and overflows only when it is full as a whole.
    uint hashed[SHADEL_COUNTERS];
    uint sectionBase[SHADEL_COUNTERS]; // prefix sum of hashed[] (queue setup)
    uint chunksRequested;              // marked chunks
    uint chunksAllocated;              // chunks that got storage
    uint chunksOverflowed;             // marked chunks that did not fit (counted, not shaded)
    uint markedBlocks;                 // blocks with any marked chunk (may exceed the list)
    uint reconstructionMisses;         // samples that found no marked chunk (must be 0)
    uint overflowSamples;              // samples whose chunk overflowed storage (shaded forward)
    uint chunksReused;                 // chunks carried over from last frame's storage (preserved)
    uint shadeCount;                   // entries in the shading queue
    uint copyCount;                    // entries in the carry-over queue
    uint magnifiedPixels;     // sampled reconstructed pixels whose MIP-0 shadel spans > 1 pixel
    uint reconstructedPixels; // sampled (even x and y) pixels the reconstruction drew
    uint chunksPerMip[SHADEL_MAX_MIPS]; // allocated chunks by MIP level
    uint pad1;
    uvec4 fillDispatch;  // x, y, z, marked blocks in the list: indirect args of the queue fill
    uvec4 shadeDispatch; // x, y, z, queue length: indirect args of the shading pass
    uvec4 copyDispatch;  // x, y, z, queue length: indirect args of the carry-over pass
};

struct ShadelFrame {
    uint64_t objects;      // GpuShadelObject[instanceCount]
    uint64_t occupancy;    // uint64 per sheet block: one bit per chunk
    uint64_t offsetMap;    // uint per block: base storage slot of its chunks
    uint64_t allocId;      // uint per block: (object + 1) << 4 | mip, 0 = free
    uint64_t counters;     // GpuShadelCounters
    uint64_t rects;        // GpuShadelRect[rectCount]
    uint64_t markedBlocks; // uvec4 {block, place in its counter, object, mip | counter << 8}
    uint64_t queue;        // GpuShadelWork[capacityChunks]: chunks to shade
    uint64_t copyQueue;    // GpuShadelWork[capacityChunks]: chunks carried over (chunk = old slot)
    uint64_t idMaps;       // uint16 triangle ids, packed in uints
    uint64_t shadelUvs;    // vec2 per vertex of the unified geometry buffer
    uint sheetBlocks;      // blocks per side of the virtual sheet
    uint rectCount;
    uint rectBlockCount;
    uint storageReadSlot;                  // bindless sampled view of this frame's radiance layer
    uint layerWriteSlot[SHADEL_LAYERS];    // this frame's layers (storage images)
    uint layerReadSlot[SHADEL_LAYERS];     // this frame's layers (sampled)
    uint prevLayerReadSlot[SHADEL_LAYERS]; // last frame's layers (sampled): preserved layers
    uint64_t prevOccupancy;                // last frame's occupancy masks
    uint64_t prevOffsetMap;                // last frame's offset map
    uint64_t changedLights; // vec4 (centre, radius) of what lights that changed reach
    uint changedLightCount;
    uint frameNumber; // frames rendered by this renderer (refresh phase)
    uint reuse;       // 0: reshade everything (--reuse off)
    uint storageChunksPerRow;
    uint capacityChunks;
    uint markedCapacity;     // entries of markedBlocks (= capacityChunks: a block needs >= 1 chunk)
    uint allocationCounters; // hashed counters in use (SHADEL_COUNTERS; fewer only for tests)
    float shadingBias;
    float trilinearBand;  // width of the LOD interval blended between two MIPs (1 = trilinear)
    uint materialSamples; // material evaluations per shadel above MIP 0 (1 or 4)
    uint regionStart[SHADEL_MAX_MIPS]; // first block column of each MIP's region
};

#ifdef __cplusplus
} // namespace shadel::gpu
#endif
#endif
