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
// KHR_materials_transmission (factor above 0, not blended): drawn after the opaque scene by
// render/transmission over a copy of it, in no camera list of the opaque passes.
#define MATERIAL_TRANSMISSION 16u
// Bits 12..15: the MATERIAL_FEATURE_* it uses (texture, procedural, clear coat, sheen), set at
// upload and on edits from materialFeatures (setMaterialFeatureFlags, render/gpu_scene.h), read
// where a shader or the cull chooses what to compile in. MATERIAL_FEATURED: any of them.
#define MATERIAL_FEATURES_SHIFT 12u
#define MATERIAL_FEATURED (MATERIAL_FEATURES_ALL << MATERIAL_FEATURES_SHIFT)
// Bits 8..10: the surface class (scene.h SurfaceClass; render/screenspace's thin G-buffer).
#define MATERIAL_CLASS_SHIFT 8u
#define MATERIAL_CLASS_MASK 7u

// Texture slots of a material (scene.h TextureSlot), for uvTransform and samplers.
#define TEXTURE_SLOT_BASE_COLOR 0u
#define TEXTURE_SLOT_METALLIC_ROUGHNESS 1u
#define TEXTURE_SLOT_NORMAL 2u
#define TEXTURE_SLOT_EMISSIVE 3u
#define TEXTURE_SLOT_OCCLUSION 4u
#define TEXTURE_SLOT_CLEARCOAT 5u
#define TEXTURE_SLOT_CLEARCOAT_ROUGHNESS 6u
#define TEXTURE_SLOT_CLEARCOAT_NORMAL 7u
#define TEXTURE_SLOT_SPECULAR 8u         // KHR_materials_specular: A = strength
#define TEXTURE_SLOT_SPECULAR_COLOR 9u   // RGB = F0 tint
#define TEXTURE_SLOT_SHEEN_COLOR 10u     // KHR_materials_sheen: RGB
#define TEXTURE_SLOT_SHEEN_ROUGHNESS 11u // A
#define TEXTURE_SLOT_TRANSMISSION 12u    // KHR_materials_transmission: R = factor
#define TEXTURE_SLOT_THICKNESS 13u       // KHR_materials_volume: G = thickness
#define TEXTURE_SLOT_COUNT 14u

// Samplers of the bindless table (rhi/bindless.h): the engine's own first, then one per
// combination of a glTF sampler's wrap modes and filters, each material texture slot naming
// one (GpuMaterial.samplers): index SAMPLER_MATERIAL_FIRST + ((wrapS * 3 + wrapT) * 2 + mag) *
// 6 + min.
#define SAMPLER_WRAP_REPEAT 0u
#define SAMPLER_WRAP_MIRRORED_REPEAT 1u
#define SAMPLER_WRAP_CLAMP_TO_EDGE 2u
#define SAMPLER_MAG_NEAREST 0u
#define SAMPLER_MAG_LINEAR 1u
#define SAMPLER_MIN_NEAREST 0u // without mipmaps: level 0 only
#define SAMPLER_MIN_LINEAR 1u  // without mipmaps: level 0 only
#define SAMPLER_MIN_NEAREST_MIPMAP_NEAREST 2u
#define SAMPLER_MIN_LINEAR_MIPMAP_NEAREST 3u
#define SAMPLER_MIN_NEAREST_MIPMAP_LINEAR 4u
#define SAMPLER_MIN_LINEAR_MIPMAP_LINEAR 5u
#define SAMPLER_MIN_COUNT 6u
#define SAMPLER_MATERIAL_FIRST 4u
#define SAMPLER_MATERIAL_COUNT 108u // 3 wrapS x 3 wrapT x 2 mag x 6 min
#define SAMPLER_COUNT 112u
// glTF's default (no sampler, or no filters given): repeat, linear, trilinear.
#define SAMPLER_MATERIAL_DEFAULT                                                                   \
    (SAMPLER_MATERIAL_FIRST + SAMPLER_MAG_LINEAR * 6u + SAMPLER_MIN_LINEAR_MIPMAP_LINEAR)

#define PROCEDURAL_NONE 0u
#define PROCEDURAL_TEXEL_CHECKER 1u
#define PROCEDURAL_BRICKS 2u

#define LIGHT_DIRECTIONAL 0u
#define LIGHT_POINT 1u
#define LIGHT_SPOT 2u        // round cone
#define LIGHT_SPOT_SQUARE 3u // square cone (a pyramid): spotScale/Offset act on tan of the angle
#define LIGHT_TUBE 4u        // a segment of 2 * halfLength along axis (representative point)
// A one-sided rectangle emitting its texture toward `direction`: centre `position`, half-extents
// halfLength along `axis` (right) and radius along cross(direction, axis) (up).
#define LIGHT_AREA 5u
#define LIGHT_KIND_COUNT 6u
// GpuLight::flags
#define LIGHT_FLAG_DARK 1u          // a negative light: subtracts its radiance (colour is negated)
#define LIGHT_FLAG_CLIP_PLANE 2u    // lights only where dot(clipPlane, vec4(p, 1)) >= 0
#define LIGHT_FLAG_SOFT_SHADOW 4u   // shadow-mapped spot: variable penumbra (PCSS) instead of PCF
#define LIGHT_FLAG_PROJECTED 8u     // spot with a gobo: colour times `texture` at the projected UV
#define LIGHT_NO_SHADOW 0xFFFFFFFFu // GpuLight::shadowIndex of a light without a shadow map
#define LIGHT_MAX_SPOT_SHADOWS 16u  // shadow-casting spots with a map in the atlas (the first)
// Light blockers (render/lighting): a light lists up to this many blockers.
#define LIGHT_MAX_BLOCKERS_PER_LIGHT 32u
#define LIGHT_TILE_SIZE 16u // pixels per side of a forward light culling tile
// FrameConstants::tonemap: the display curve (RenderSettings::tonemap, common/tone_curve.glsl).
#define TONEMAP_ACES_NARKOWICZ 0u
#define TONEMAP_ACES_HILL 1u
#define TONEMAP_KHR_PBR_NEUTRAL 2u
#define TONEMAP_LINEAR 3u
#define TONEMAP_GROUP_X 32u // the tonemap pass's workgroup (post/tonemap.comp)
#define TONEMAP_GROUP_Y 8u
// Feature spectra (render/lighting/feature_spectra.h): the features a tile needs,
// recorded by the tile pass; each shading permutation compiles in only its set (specialization
// constant SPECTRUM_FEATURES_CONSTANT_ID of shaders/common/lighting.glsl; SPECTRUM_MATERIAL sets
// MATERIAL_FEATURES_CONSTANT_ID of shaders/common/material.glsl).
#define SPECTRUM_OMNI 0x1u           // point lights
#define SPECTRUM_SPOT 0x2u           // round-cone spots
#define SPECTRUM_SQUARE_SPOT 0x4u    // square-cone spots
#define SPECTRUM_TUBE 0x8u           // tube lights (representative point)
#define SPECTRUM_DARK 0x10u          // negative lights (the clamp that keeps the sum >= 0)
#define SPECTRUM_CLIP_PLANES 0x20u   // a light's clip plane crosses the tile
#define SPECTRUM_BLOCKERS 0x40u      // (light, blocker) pairs tested per pixel
#define SPECTRUM_PORTALS 0x80u       // ... of blockers with portals
#define SPECTRUM_SHADOWS 0x100u      // the sun's shadow map (PCF)
#define SPECTRUM_SPOT_SHADOWS 0x200u // spot shadow maps in the atlas (PCF)
#define SPECTRUM_SOFT_SHADOWS 0x400u // variable penumbra (PCSS): the sun's or a spot's
#define SPECTRUM_PROJECTED 0x800u    // spots projecting a texture (gobos)
#define SPECTRUM_AREA 0x1000u        // textured rectangular area lights
#define SPECTRUM_MATERIAL 0x2000u    // a material with any MATERIAL_FEATURE_* (textures, ...)
#define SPECTRUM_FEATURE_COUNT 14u
#define SPECTRUM_ALL 0x3FFFu
#define SPECTRUM_ALL_LIGHTING (SPECTRUM_ALL & ~SPECTRUM_MATERIAL) // every light may reach it
#define SPECTRUM_MAX_MODES 16u
#define SPECTRUM_FEATURES_CONSTANT_ID 140
#define SPECTRUM_MODE_CONSTANT_ID 141 // the mode (bin) a tile / chunk shading permutation runs
// Spectra per light (forward tiles): the features only some lights of a list bring, each a
// texture read per light (a spot's shadow map, PCSS, a gobo, an area light's emitter). A
// tile's list holds the lights without them first (LightingFrame::tileRanges), and a pipeline
// with SPECTRUM_LIGHT_SPLIT_CONSTANT_ID set shades those in a loop compiled without them
// (shaders/common/lighting.glsl, shadeSurface): the raster forward pass, and the --spectra on
// permutations that have them.
#define SPECTRUM_SAMPLING_LIGHTS                                                                   \
    (SPECTRUM_SPOT_SHADOWS | SPECTRUM_SOFT_SHADOWS | SPECTRUM_PROJECTED | SPECTRUM_AREA)
#define SPECTRUM_LIGHT_SPLIT_CONSTANT_ID 150
// Shadel shading's phase: off, classify or shade (chunk_spectra.glsl).
#define CHUNK_SPECTRA_PHASE_CONSTANT_ID 143
// Whether the scene has alpha-masked materials (the visibility prepass's alpha test): without
// them the test and its discard are compiled out, so the depth test runs before the fragment
// shader (early Z) instead of after it for every covered fragment.
#define ALPHA_MASK_CONSTANT_ID 144
// Whether the raster vertex shader (shaders/forward/forward.vert) draws visibility vertices
// (each triangle's provoking vertex names it, scene/visibility_vertices.h): no (the scene's
// vertices), yes with every output (forward shading and the raster reconstruction under
// --inspect, which prints the triangle), or yes for the visibility prepass (IDs and UVs only).
#define VISIBILITY_VERTICES_CONSTANT_ID 145
#define VISIBILITY_VERTICES_OFF 0u
#define VISIBILITY_VERTICES_ALL 1u
#define VISIBILITY_VERTICES_PREPASS 2u
// Whether the compute resolve rebuilds its rare pixels inline (debug views, --inspect) or lists
// them for its rebuild pass (shaders/shadel/resolve.comp).
#define RESOLVE_REBUILD_INLINE_CONSTANT_ID 146
// Whether forward shading writes display pixels (the tone curve and sRGB applied, into an RGBA8
// target) instead of scene colour: the frame's tonemap is fused into it (render/post/tonemap.h).
#define FORWARD_DISPLAY_OUTPUT_CONSTANT_ID 151
// The same for the decoupled compute resolve and its rebuild pass (shaders/shadel/resolve.comp):
// display pixels into the readback instead of scene colour. A constant, not a push-constant
// branch: lavapipe runs both sides of a branch (resolveCompute 35.8 ms with the branch, 32.3
// with the constant, in two bench runs of builtin:default 1280x720, orbit).
#define RESOLVE_DISPLAY_OUTPUT_CONSTANT_ID 152
// Which list marking's indirect-arguments pass sizes: the two-triangle quads' (after the first
// pass) or the per-pixel quads' (after the second; shaders/shadel/mark_listed_args.comp).
#define MARK_PIXEL_LIST_CONSTANT_ID 153
// Which queued chunks a shadel shading pipeline shades (shaders/shadel/shade.comp): all of them
// (the spectra permutations, everything compiled in), or one shading class's list. The classes
// (SHADEL_OBJECT_* flags, per object from its material): plain (no texture, procedural, clear
// coat or sheen: those compiled out, one material sample), featured (one material sample),
// supersampled (point-function procedurals), and textured (textures only: the rest compiled out;
// on lavapipe every compiled-in feature costs every shadel, taken or not: BoxTextured's shading
// 91 -> 79 ms at 1280x720).
#define SHADE_QUEUE_CONSTANT_ID 147
#define SHADE_QUEUE_ALL 0u
#define SHADE_QUEUE_PLAIN 1u
#define SHADE_QUEUE_FEATURED 2u
#define SHADE_QUEUE_SUPERSAMPLED 3u
#define SHADE_QUEUE_TEXTURED 4u
#define SHADE_CLASSES 4u // the class lists: SHADE_QUEUE_* - 1
// After the class lists, ShadelFrame::classQueues holds one more: the near-change list, chunks
// that could be carried over but lie on an object a changed region meets (fill_queue.comp);
// near_change.comp carries each over or appends it to its class's list.
#define SHADE_NEAR_CHANGE_LIST SHADE_CLASSES
// The material features a shader evaluates (shaders/common/material.glsl: kMaterialFeatures).
#define MATERIAL_FEATURES_CONSTANT_ID 149
#define MATERIAL_FEATURE_TEXTURES 1u   // any texture slot
#define MATERIAL_FEATURE_PROCEDURAL 2u // point-function procedurals (checker, bricks)
#define MATERIAL_FEATURE_CLEARCOAT 4u
#define MATERIAL_FEATURE_SHEEN 8u
#define MATERIAL_FEATURES_ALL 15u
// The optional parts a shadel shading pipeline has compiled in: ray-traced terms (--rt-*),
// the scene's decals, --debug-lines chunks, preserved layers (--reuse: carrying chunks near a
// change over, recording each chunk's view), and the chunk's light culling in shared memory
// (tiled culling with more lights than per-subgroup lists take). The plain shading pass leaves
// out what the renderer was created without (on CPU devices an unused feature's code still runs,
// masked; and lavapipe runs a shader with any barrier in it as coroutines, one per SIMD group).
#define SHADE_OPTIONAL_CONSTANT_ID 148
#define SHADE_OPTIONAL_RT 1u
#define SHADE_OPTIONAL_DECALS 2u
#define SHADE_OPTIONAL_DEBUG_LINES 4u
#define SHADE_OPTIONAL_REUSE 8u
#define SHADE_OPTIONAL_CHUNK_LIGHTS 16u
#define SHADE_OPTIONAL_ALL 31u
// Specialization constant of shaders/common/lighting.glsl: 1 compiles the distance-field far
// shadows and AO in (render/distance_fields; forward and shadel shading with --distance-fields).
#define DISTANCE_FIELD_LIGHTING_CONSTANT_ID 142

#define NO_TEXTURE 0xFFFFFFFFu

// Draw lists written by the instance culling pass.
#define DRAW_LIST_OPAQUE 0u    // forward-shaded opaque and alpha-masked instances
#define DRAW_LIST_BLEND 1u     // forward-shaded blended instances
#define DRAW_LIST_DECOUPLED 2u // opaque instances shaded in shadel space this frame
// Blended instances shaded in shadel space this frame (reconstructed into the OIT targets).
#define DRAW_LIST_DECOUPLED_BLEND 3u
// Forward-shaded opaque instances by the material features their material uses: textures and
// nothing else, or any other MATERIAL_FEATURE_* (procedurals, clear coat, sheen). The forward
// shading draws DRAW_LIST_OPAQUE (no feature) and these with only what they need compiled in
// (render/forward); every other pass draws the three as one (drawCameraList).
#define DRAW_LIST_OPAQUE_FEATURED 4u
#define DRAW_LIST_OPAQUE_TEXTURED 5u
#define DRAW_LIST_COUNT 6u
// Each camera list is four, by the faces its instances draw (render/forward drawCameraList sets
// the cull mode and front face per side): single-sided materials cull back faces
// (DRAW_SIDE_FRONT), double-sided ones draw both (DRAW_SIDE_BOTH); and instances whose transform
// mirrors (a negative determinant, which glTF says flips the winding; it may change sign while
// an animation plays) take the clockwise front face (DRAW_SIDE_MIRRORED set). The cull pass
// decides from the transform every frame, so a mesh is stored once whatever its instances'
// signs. Camera list l, side s: slot l * DRAW_SIDE_COUNT + s of DRAW_CAMERA_SLOTS.
#define DRAW_SIDE_FRONT 0u
#define DRAW_SIDE_BOTH 1u
#define DRAW_SIDE_MIRRORED 2u // added to FRONT or BOTH
#define DRAW_SIDE_COUNT 4u
#define DRAW_CAMERA_SLOTS 24u

// Debug views (--visualize).
#define VISUALIZE_NONE 0u
#define VISUALIZE_MARKING 1u
#define VISUALIZE_MIPS 2u
#define VISUALIZE_CHUNKS 3u
#define VISUALIZE_SHEET 4u
#define VISUALIZE_LAYER_MATERIAL 5u // --visualize layer:material
#define VISUALIZE_LIGHT_COUNT 16u   // --visualize light-count: lights per tile / chunk (heat)
#define VISUALIZE_BLOCKERS 17u      // --visualize blockers: tiles with per-pixel blocker checks
#define VISUALIZE_GI 6u             // --visualize gi: the LPV indirect light only
#define VISUALIZE_RT_AO 7u          // --visualize rt-ao: the ray-traced ambient occlusion only
#define VISUALIZE_TILES 20u         // --visualize tiles: the 8x8 tile classes (render/tiles)
#define VISUALIZE_SPECTRA 18u       // --visualize spectra: each tile's shading permutation
#define VISUALIZE_REUSE 9u          // --visualize reuse: carried-over chunks, and why others shaded

// One vertex of the unified geometry buffer (matches shadel::Vertex).
struct GpuVertex {
    vec3 position;
    vec3 normal;
    vec4 tangent;
    vec2 uv0; // TEXCOORD_0
    vec2 uv1; // TEXCOORD_1 (uv0 where the mesh has none)
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
    // glTF material extensions (scene.h Material; shaders/common/material.glsl).
    vec2 uvTransform[42]; // 3 x TEXTURE_SLOT_COUNT: per texture slot (TEXTURE_SLOT_*): columns c0,
                          // c1, translation c2
    // Per texture slot, its sampler's index in the bindless table (SAMPLER_MATERIAL_*): a byte
    // each, slot s in samplers[s / 4] bits 8 * (s % 4).
    uint samplers[4];
    uint clearcoatTexture;
    uint clearcoatRoughnessTexture;
    uint clearcoatNormalTexture;
    float clearcoatFactor;
    float clearcoatRoughnessFactor;
    float clearcoatNormalScale;
    float dielectricF0Scalar; // ((ior - 1) / (ior + 1))^2 x specularFactor
    vec3 specularColorFactor; // tints the dielectric F0 (KHR_materials_specular)
    float specularFactor;     // dielectric F90
    vec3 sheenColorFactor;    // 0: no sheen
    float sheenRoughnessFactor;
    uint specularTexture; // bindless slots of the factors' textures, NO_TEXTURE when absent
    uint specularColorTexture;
    uint sheenColorTexture;
    uint sheenRoughnessTexture;
    // KHR_materials_transmission and KHR_materials_volume (render/transmission).
    float transmissionFactor; // 0: opaque
    uint transmissionTexture;
    float thicknessFactor; // in the mesh's space (scaled by the instance's transform); 0: thin
    uint thicknessTexture;
    vec3 attenuationColor;     // what white light becomes after attenuationDistance
    float attenuationDistance; // world units; infinity: no attenuation
    float ior;                 // KHR_materials_ior (the refraction; dielectricF0Scalar holds F0)
    // Bit s: texture slot s (TEXTURE_SLOT_*) reads the second UV set (GpuVertex.uv1), else uv0.
    uint texCoords;
};

struct GpuLight {
    vec3 position; // the centre of tube lights
    uint type;
    vec3 direction;     // the way light travels (spots)
    float range;        // 0 = infinite
    vec3 color;         // colour * intensity; negated for darks
    float spotScale;    // round: 1 / max(cos(inner) - cos(outer), 1e-4); square: on tan(angle)
    float spotOffset;   // round: -cos(outer) * spotScale; square: tan(outer) * spotScale
    uint flags;         // LIGHT_FLAG_*
    float halfLength;   // tube: half the segment's length; area: half the width (along axis)
    float radius;       // tube: the tube's radius (widens the specular lobe); spot: emitter width;
                        // area: half the height (along cross(direction, axis))
    vec3 axis;          // tube: the segment's direction; square spot, gobo, area: "right" axis
    uint blockerFirst;  // into LightingFrame::lightBlockers
    vec4 clipPlane;     // LIGHT_FLAG_CLIP_PLANE: world-space plane, lit side positive
    uint blockerCount;  // blockers this light lists (<= LIGHT_MAX_BLOCKERS_PER_LIGHT)
    uint shadowIndex;   // into LightingFrame::spotShadows; LIGHT_NO_SHADOW without a shadow map
    uint textureSlot;   // gobo / area: bindless slot of the projected / emitted texture
    float textureScale; // gobo: UV per unit of tan(angle off the axis) (0.5 / tan(outer) fills
                        // the cone); area: 1
};

// A light blocker: an artist-placed rectangle (a wall's mid-plane) that stops the
// lights listing it, without a shadow map. Portals are rectangular holes in it.
struct GpuLightBlocker {
    vec3 center;
    uint firstPortal; // into LightingFrame::portals
    vec3 axisU;       // unit, in the plane
    float halfU;
    vec3 axisV; // unit, in the plane, orthogonal to axisU
    float halfV;
    vec3 normal; // cross(axisU, axisV)
    uint portalCount;
};

// A hole in a blocker: a rectangle in the blocker's (u, v) coordinates (metres from its centre).
struct GpuLightPortal {
    vec2 minUv;
    vec2 maxUv;
};

// Light culling counters, read back for the stats.
struct LightingCounters {
    uint lightTilePairs;       // (light, tile) pairs kept by tiled culling (forward tiles)
    uint perPixelBlockerTiles; // tiles with any (light, blocker) pair checked per pixel
    uint tilesOverflowed;      // tiles with more lights than a list holds (lights dropped)
    uint lightChunkPairs;      // (light, chunk) pairs of the shadel path's chunk culling
    uint perPixelBlockerChunks;
    uint chunksOverflowed;
    uint lightsCulledByBlockers; // (light, tile) pairs a blocker removed whole
    uint tileListEntries;        // entries taken from the tile list pool (may exceed it)
    uint lightGridCandidates;    // lights the shadel chunks tested (taken from the light grid)
    // Lists the shadel path culled per subgroup (LightingFrame::subgroupLists); the chunk
    // counts above (pairs, candidates, per-pixel blocker) then count those lists.
    uint lightSubgroupLists;
    // Of lightTilePairs, those whose light reads no texture: each tile lists them first (spectra
    // per light, SPECTRUM_LIGHT_SPLIT_CONSTANT_ID).
    uint lightTilePlainPairs;
};

// The light grid (render/lighting/light_grid.h): lights bucketed in world space so a shadel
// chunk tests only the lights near its box, not every light of the scene. Levels of cubic
// cells, each twice the size of the one below; cells are hashed into buckets per level. A
// light is listed in every cell its bounding sphere meets, at the levels where that is at
// most LIGHT_GRID_MAX_SPAN cells per axis, and in the level's "big" list above that. Lights
// of infinite range are in the global list. A chunk queries the finest level whose cell is at
// least its box's size (at most 2x2x2 cells): those cells' buckets + the big and global lists
// hold every light that can meet the box, and the exact test picks from those.
#define LIGHT_GRID_LEVELS 8u
#define LIGHT_GRID_BUCKETS 4096u // per level; a power of two
#define LIGHT_GRID_MAX_SPAN 8
#define LIGHT_GRID_MAX_CELL 268435456.0 // |cell coordinate| below 2^28: exact as float and int
#define LIGHT_GRID_MASK_LIGHTS 8192u    // the chunk's shared bit set of candidates (more: no grid)
#define LIGHT_GRID_HASH(x, y, z)                                                                   \
    (((uint(x) * 73856093u) ^ (uint(y) * 19349663u) ^ (uint(z) * 83492791u)) &                     \
     (LIGHT_GRID_BUCKETS - 1u))

struct GpuLightGrid {
    vec3 origin;      // world position of cell (0,0,0)'s corner, every level
    float cellSize;   // level 0's cell edge (metres); level l: cellSize * 2^l
    uint levels;      // levels built (<= LIGHT_GRID_LEVELS)
    uint globalFirst; // entries of the lights of infinite range
    uint globalCount;
    uint pad0;
    uvec2 big[LIGHT_GRID_LEVELS]; // per level: first entry, count of lights too big for its cells
    uint64_t buckets;             // uvec2 [level * LIGHT_GRID_BUCKETS + bucket]: first entry, count
    uint64_t entries;             // uint light indices
};

// What the tiled-lighting passes share with shading (FrameConstants::lighting).
// LightingFrame::subgroupLists: culling per subgroup into a bit set of the scene's lights.
#define LIGHT_SUBGROUP_MAX_LIGHTS 64u

struct LightingFrame {
    uint64_t tileLights;    // pool of uvec2 entries: light index, mask of its blockers to test
    uint64_t tileRanges;    // uvec2 per tile: first entry in the pool, entries
    uint64_t blockers;      // GpuLightBlocker[]
    uint64_t portals;       // GpuLightPortal[]
    uint64_t lightBlockers; // uint blocker indices, GpuLight::blockerFirst/Count index them
    uint64_t counters;      // LightingCounters
    uint64_t visibleLights; // uint bit set: lights in at least one list
    uint tilesX;
    uint tilesY;
    uint tiled;        // 1: shading reads per-tile / per-chunk lists; 0: every light everywhere
    uint blockersOn;   // --blockers on
    uint poolCapacity; // entries of the tile list pool
    uint blockerCount;
    // Lights whose range meets the camera frustum, in light order (the CPU's cull): only these
    // can reach a screen tile, so the tile pass tests these alone.
    uint64_t frustumLights; // uint light indices
    uint frustumLightCount;
    uint screenTiles; // 1: the tile pass built the screen tiles' lists this frame
    uint64_t spectra; // SpectraFrame with --spectra on|single, else 0
    // Shadows (render/lighting/spot_shadows.h): spot shadow maps share one atlas.
    uint64_t spotShadows;   // GpuSpotShadow[], GpuLight::shadowIndex indexes it
    uint spotShadowAtlas;   // bindless slot of the atlas (depth), NO_TEXTURE without one
    uint sunSoftShadows;    // 1: the sun's shadow is PCSS (variable penumbra), 0: PCF
    float sunPenumbraScale; // penumbra width per metre from occluder to receiver (tan of the
                            // sun's angular radius)
    float sunDepthRange;    // metres from the sun shadow map's depth 0 to 1 (orthographic)
    // Feature spectra of the shadel path (decoupled, --spectra on|single): a SpectraFrame whose
    // bins hold work-queue indices of shading chunks (dispatch: uvec4 per mode, w = count).
    uint64_t chunkSpectra;
    // The sun's cascaded shadow maps (render/lighting/sun_cascades.h): GpuSunCascades, 0 with
    // --sun-cascades 1 (the one map fitted to the scene, FrameConstants::sunViewProj).
    uint64_t sunCascades;
    // The light grid the shadel chunks' culling queries (GpuLightGrid), 0: test every light.
    uint64_t lightGrid;
    // 1: few lights (at most LIGHT_SUBGROUP_MAX_LIGHTS); shading culls them per subgroup
    // (lighting/light_cull.glsl useSubgroupLightList): every forward pixel and shadel, with no
    // tile pass and no chunk culling (`tiled` is then 0).
    uint subgroupLists;
};

#define SUN_MAX_CASCADES 4u
// The sun's cascades: slices of the camera's view depth, each an orthographic map (a rectangle
// of one atlas) fitted to its slice's bounding sphere and snapped to its texels.
struct GpuSunCascades {
    mat4 viewProj[SUN_MAX_CASCADES];  // world -> the cascade's clip space (depth 0..1)
    vec4 atlasRect[SUN_MAX_CASCADES]; // UV offset xy, size zw
    vec4 splitFar;      // view depth (metres along cameraForward) where cascade i ends
    vec4 texelWorld;    // a texel's width in metres, per cascade
    vec3 cameraForward; // unit: view depth = dot(p - cameraPosition, cameraForward)
    uint count;
    uint atlasSlot;   // bindless slot of the atlas (depth)
    float depthRange; // metres from depth 0 to 1 (the same for every cascade)
    uint pad0;
    uint pad1;
};

// A spot light's shadow map: its rectangle of the atlas and its perspective view.
struct GpuSpotShadow {
    mat4 viewProj;    // world -> the spot's clip space (depth 0 near .. 1 far)
    vec4 atlasRect;   // the map's rectangle in atlas UV: offset xy, size zw
    float nearPlane;  // of the perspective (metres)
    float farPlane;   // the light's range
    float lightSize;  // PCSS: the emitter's width (metres)
    float texelAngle; // 2 tan(half the field of view) / resolution: a texel's width per metre
};

// Feature spectra (render/lighting/feature_spectra.h): the tile pass bins every tile into the
// first mode (cheapest first) whose features cover what the tile needs.
#define CHUNK_LIST_NONE 0xFFFFFFFFu // SpectraFrame::chunkRanges .y: no stored list
// SpectraFrame::chunkListCount[SPECTRA_LONG_LIST_DISPATCH..+3]: the long-list pass's indirect
// dispatch (x, y, z, chunks).
#define SPECTRA_LONG_LIST_DISPATCH 4u
#define SPECTRA_CHUNK_LIST_COUNTS 8u // uints in SpectraFrame::chunkListCount
#define SPECTRA_LONG_LIST_GROUP 8u   // chunk_long_lists.comp's workgroup

struct SpectraFrame {
    uint64_t dispatch;     // VkDispatchIndirectCommand per mode: x = tiles binned to it
    uint64_t tileBins;     // uint tile indices: mode m's list starts at m * binCapacity
    uint64_t superfluous;  // uint per (mode, feature bit): binned tiles that did not need it
    uint64_t featureTiles; // uint per feature bit: tiles that needed it; then per feature set
    // Shadel chunks: the light list the classify phase culled for each queued chunk, so the
    // shading permutations read it instead of culling the chunk again (0 for screen tiles).
    uint64_t chunkLists;  // uvec2 entries (light, blocker mask), a pool
    uint64_t chunkRanges; // uvec2 per shading-queue index: (first entry, count); count
                          // CHUNK_LIST_NONE when the pool was full (the chunk's permutation
                          // takes every light)
    // uint[SPECTRA_CHUNK_LIST_COUNTS]: pool entries requested this frame; chunks whose list did
    // not fit the pool; chunks with more lights than classify keeps in its private list (their
    // lists written by chunk_long_lists.comp); unused; that pass's indirect dispatch
    uint64_t chunkListCount;
    // uvec4 pairs per long-list chunk: (shading-queue index, box min), (box max, 0) (floats)
    uint64_t longChunks;
    uint modeCount;
    uint binCapacity;       // tiles (each mode's list can hold every tile)
    uint chunkListCapacity; // entries of the chunkLists pool
    uint modeFeatures[SPECTRUM_MAX_MODES];
};

struct DrawIndexedCommand { // VkDrawIndexedIndirectCommand
    uint indexCount;
    uint instanceCount;
    uint firstIndex;
    int vertexOffset;
    uint firstInstance;
};

// ---- Image-based lighting (render/environment, shaders/environment) --------------------------
// GpuEnvironment::flags
#define ENVIRONMENT_FLAG_NONE 1u     // no environment: lighting and background read 0
#define ENVIRONMENT_FLAG_SUN_DISC 2u // the background draws the sun's disc

// Every map is equirectangular in the convention of render/environment/equirect.h (row 0 looks
// up, the middle column along +Z), sampled bilinearly with u wrapping and v kept inside the
// first and last rows' texel centres.
struct GpuEnvironment {
    uint specularSlot;    // radiance, GGX-prefiltered: MIP l for perceptual roughness
                          // l / (specularLevels - 1), level 0 unfiltered
    uint irradianceSlot;  // irradiance / pi (the Lambert radiance for albedo 1)
    uint backgroundSlot;  // what the camera sees behind the scene (without the sun's disc)
    uint brdfSlot;        // (n.v, perceptual roughness): GGX scale, GGX bias, sheen albedo
    uint specularLevels;  // MIP count of the specular map
    uint flags;           // ENVIRONMENT_FLAG_*
    float intensity;      // multiplies every radiance (not the BRDF table)
    float rotationCos;    // world to environment: the rotation about +Y by the environment
    float rotationSin;    // rotation angle (x' = c x + s z, z' = -s x + c z)
    float sunCosRadius;   // cosine of the sun disc's angular radius
    float specularHeight; // texel rows of specular level 0 (level l: max(height >> l, 1))
    float irradianceHeight;
    vec3 sunDirection; // the way sunlight travels, in the environment's frame
    float backgroundHeight;
    vec3 sunRadiance; // radiance of the disc (0 without one)
    float brdfSize;   // texels per side of the BRDF table
    uint sheenSlot;   // radiance, Charlie-prefiltered: MIP l for sheen roughness l / (levels - 1)
    uint sheenLevels;
    float sheenHeight; // texel rows of sheen level 0
    float sheenPad;
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
    float shadingBias;   // fractional MIP bias of the decoupled path
    uint inspectPixel;   // --inspect: x | y << 16 at the internal resolution, or INSPECT_OFF
    uint64_t vertices;   // GpuVertex[]
    uint64_t indices;    // uint[]
    uint64_t meshes;     // GpuMesh[]
    uint64_t instances;  // GpuInstance[]
    uint64_t materials;  // GpuMaterial[]
    uint64_t lights;     // GpuLight[]
    uint64_t messages;   // ShaderMessages (shader asserts)
    uint64_t shadel;     // ShadelFrame (decoupled path), 0 when forward
    uint64_t lighting;   // LightingFrame (render/lighting), 0 when absent
    uint64_t gi;         // GiFrame (render/gi, shaders/gi/gi_types.h), 0 when GI is off
    uint64_t culling;    // CullingFrame (render/culling): LODs, occlusion, per-view counts
    uint64_t debugLines; // GpuDebugLines (render/debug/debug_lines.h), 0 when --debug-lines is off
    uint64_t rt;         // RtFrame (render/raytracing, shaders/raytracing/rt_types.h), 0 when off
    // uint per bindless sampled slot: the finest MIP shading wanted of a 32768^2 texture there,
    // atomically min-reduced (render/streaming, shaders/streaming/feedback.glsl); 0 = off.
    uint64_t textureFeedback;
    // Distance-field lighting (render/distance_fields, --distance-fields on): the
    // DistanceFieldFrame (0: off); the sun's shadow comes from the fields beyond dfShadowStart
    // metres from the camera (the far field), from the shadow map nearer; DF AO on the ambient.
    uint64_t distanceFields;
    float dfShadowStart;
    uint dfPad;
    uint64_t decals; // DecalFrame (render/decals), 0 when the frame has no decals
    // uvec2 per visibility vertex: (scene vertex, the triangle of its mesh it starts), what the
    // visibility prepass draws (scene/visibility_vertices.h).
    uint64_t visibilityVertices;
    uint tonemap; // TONEMAP_*: the display curve after exposure
    // What uncovered pixels show: the environment's background (1), or backgroundColor, the
    // radiance the display curve turns into the --background colour (0).
    uint backgroundEnvironment;
    vec3 backgroundColor;
    uint framePad;
    GpuEnvironment environment; // image-based lighting (render/environment)
};

// ---- GPU-driven world (render/culling) ------------------------------------------------------
#define CULL_MAX_LODS 8u
#define CULL_VIEW_CAMERA 0u
#define CULL_VIEW_SHADOW 1u   // the sun's whole-scene map
#define CULL_VIEW_CASCADE0 2u // sun cascade i is view CULL_VIEW_CASCADE0 + i
#define CULL_VIEW_SPOT0 (CULL_VIEW_CASCADE0 + SUN_MAX_CASCADES) // spot shadow i: + i
#define CULL_VIEWS (CULL_VIEW_SPOT0 + LIGHT_MAX_SPOT_SHADOWS)
#define CULL_SHADOW_VIEW_CASCADE 0u
#define CULL_SHADOW_VIEW_SPOT 1u

// One level of a mesh's LOD chain: a range of the unified index buffer over the mesh's vertices
// (the same vertexOffset for every level: simplification only drops vertices).
struct GpuLod {
    uint firstIndex;
    uint indexCount;
    float error; // object-space deviation from LOD 0 (meshoptimizer's error, in scene units)
    // The proxy (shadow) index set of this level (shadow views draw it): the
    // same triangles over position-only deduplicated vertices (meshopt_generateShadowIndexBuffer),
    // so a depth-only view fetches each position once instead of once per normal/UV/chart seam.
    uint proxyFirstIndex;     // indexCount indices, the same vertexOffset
    uint uniqueVertices;      // distinct vertices the main set references
    uint proxyUniqueVertices; // ... and the proxy set
    uint pad0;
    uint pad1;
};

struct GpuMeshLods {
    uint lodCount; // >= 1; LOD 0 is GpuMesh's range, the last is the least detailed
    uint pad0;
    uint pad1;
    uint pad2;
    GpuLod lod[CULL_MAX_LODS];
};

// Counted by the culling passes, read back after the frame (the stats' per-view table).
struct GpuCullStats {
    uint instancesDrawn[CULL_VIEWS];
    uint trianglesDrawn[CULL_VIEWS];
    uint frustumVisible[CULL_VIEWS]; // passed the frustum (and, for shadows, the caster) test
    uint occlusionCulled;            // camera: frustum-visible but behind the depth pyramid
    uint drawnLastFrameVisible;      // camera: drawn in phase 1 (visible last frame)
    uint verticesDrawn[CULL_VIEWS];  // distinct vertices of the index sets drawn, summed
};

struct CullingFrame {
    uint64_t meshLods;    // GpuMeshLods[meshCount]
    uint64_t stats;       // GpuCullStats
    uint64_t visibility;  // uint per instance: 1 when visible to the camera last frame
    uint64_t hiz;         // float depth pyramid, every level packed (level 0 = depth target)
    uint lod;             // 1: pick LODs by projected error; 0: always LOD 0
    float lodErrorPixels; // the coarsest LOD whose error projects below this many pixels
    float lodScale;       // pixels per unit of error at distance 1 (viewport height / 2 * P[1][1])
    uint occlusion;       // 1: two-phase hierarchical-Z culling of the camera view
    uint hizLevels;
    uvec2 hizSize;     // level 0 = the depth target's size
    float sceneMinY;   // the lowest point of the scene: shadows end there
    uint proxyShadows; // 1: shadow views draw each LOD's proxy index set
    // --shadow-culling per-view: the cascades' and spots' own lists, filled by the same dispatch
    // as the camera's and the sun's (0 views with whole-scene: they draw the sun's list).
    uint64_t shadowViews;      // GpuShadowCullView[shadowViewCount]
    uint64_t shadowViewDraws;  // DrawIndexedCommand[lists * maxDraws], one list per view
    uint64_t shadowViewCounts; // uint per list
    uint shadowViewCount;
    // The sun's list this frame (SUN_LIST_*; render/lighting/sun_shadow_cache.h): its casters
    // whose shadow can reach the camera's frustum, every caster in its volume (a map to keep),
    // or none (the kept map is not redrawn and nothing else draws the list).
    uint sunList;
};
#define SUN_LIST_NONE 0u
#define SUN_LIST_CAMERA 1u
#define SUN_LIST_ALL 2u

// A cascade's or spot's view for per-view shadow culling. Depth clamp keeps casters in front of
// the near plane in the map, so only the four sides and the far plane cull.
struct GpuShadowCullView {
    vec4 planes[5];
    uint view; // CULL_VIEW_*: its row of the stats
    uint list; // its draw list in CullingFrame::shadowViewDraws
    uint kind; // CULL_SHADOW_VIEW_*: a cascade's casters must also shadow the camera's frustum
    uint pad;
};

// Shader -> CPU message channel (shader asserts and prints). Written with atomics, read after the
// frame.
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
#define SHADEL_COUNTERS 16u // hashed allocation counters (N allocations in parallel)
#define SHADEL_BLOCK 64u    // shadels per block side (8 x 8 chunks)
#define SHADEL_CHUNK 8u     // shadels per chunk side
#define SHADEL_INVALID 0xFFFFFFFFu
#define SHADEL_OBJECT_DECOUPLED 1u // allocated in the sheet this frame: drawn decoupled
// Its bounds meet a light that changed this frame: carried-over chunks check their shadels.
#define SHADEL_OBJECT_NEAR_CHANGE 2u
// Its material is a point-function procedural and --material-samples > 1: its shadels
// supersample the material (shaders/shadel/prefilter.glsl), in a shading pipeline of their own.
#define SHADEL_OBJECT_SUPERSAMPLED 4u
// Its material uses any MATERIAL_FEATURE_* (else it is shaded by the plain pipeline).
#define SHADEL_OBJECT_FEATURED_MATERIAL 8u
// Of those, materials whose only feature is textures: shaded by the textured pipeline (clear coat,
// sheen and procedurals compiled out), as the forward path's textures-only class.
#define SHADEL_OBJECT_TEXTURED_MATERIAL 16u
#define SHADEL_MAX_CHANGED_VOLUMES 256u
#define SHADEL_CHUNK_VIEW_NONE 0xFFFFFFFFu // ShadelFrame::chunkViews: a NaN centre
// Material layers of the shade storage (layers of different formats): every layer shares the slot
// allocation; each has its own format.
#define SHADEL_LAYER_RADIANCE 0u // lit colour, RGBA16F
#define SHADEL_LAYER_MATERIAL 1u // base colour + roughness, RGBA8 (for GI injection, debugging)
#define SHADEL_LAYERS 2u

// The material shading rate (render/shadel/material_rate.h materialRateLod, shadelLevels in
// shaders/shadel/shadel.glsl) coarsens a sample no further than this LOD (samples the view
// already puts coarser are left as they are). Past the bake's clean levels (2^k > gutterShadels,
// bake.h: 2 shadels, so k >= 2) a chart's border shadels read its neighbours' gutters, and the
// rate pushing samples there showed along creases. PSNR vs 4x4 SSAA at 1280x720, full rate /
// unbounded / bounded at 3 / at 2: 2CylinderEngine.glb 37.68 / 37.40 / 37.55 / 37.61 dB,
// builtin:many 38.74 / 38.62 / 38.75 / 38.85; builtin:default 28.97 in all four, at 0.74
// shadels per covered pixel unbounded and at 3 but 0.85 at 2 (shadelShading +7 ms).
#define SHADEL_MATERIAL_RATE_MAX_LOD 3.0
// GpuShadelObject::textureLod of an object whose material has no texture detail to keep: the
// rate's bias applies in full.
#define SHADEL_TEXTURE_LOD_NONE 1000.0

// Per instance: where its shadel space lives in the virtual sheet at each MIP.
struct GpuShadelObject {
    uvec2 mip0Size; // MIP-0 shadel rect (BakedMesh::width/height)
    uint mipCount;
    uint flags;
    uint firstMip; // finest MIP with a rect this frame (the CPU's estimate of what it can need)
    // Bit k: MIP k was placed before this frame (or only its window moved: prevRect*) and every
    // shading input of the object (transform, material, lights in range) is unchanged since
    // last frame, so last frame's shadels there may be carried over.
    uint reuseLevels;
    // Cosine of the angle the direction from a carried-over chunk to the camera may turn since
    // the chunk was shaded before its view-dependent terms (specular, Fresnel) visibly lag: its
    // material's specular lobe width, widened by how little of its light is specular (a rough
    // dielectric tolerates far more than a polished metal). Checked per chunk
    // (ShadelFrame::chunkViews).
    float viewDriftCos;
    // MIPs coarser than the pixel footprint asks for that the object's material allows
    // (render/shadel/material_rate.h: smooth, lighting-only surfaces), added to the sample's LOD
    // with the frame's shading bias, but never past SHADEL_MATERIAL_RATE_MAX_LOD.
    float rateBias;
    // Textured materials: the finest whole level whose shadels lie at most half a texel of the
    // material's densest texture apart; the rate coarsens a sample no further than the level
    // before it (render/shadel/texture_rate.h). SHADEL_TEXTURE_LOD_NONE without textures.
    float textureLod;
    uint firstRect; // index of its firstMip rect in ShadelFrame::rects (levels follow in order)
    uint idMapOffset[SHADEL_MAX_MIPS]; // in 16-bit units into ShadelFrame::idMaps
    uvec4 rect[SHADEL_MAX_MIPS];       // x, y, w, h in blocks of the virtual sheet
    // Level windows: a fine level's rect holds only the part of the level the view needs (last
    // frame's marks plus a margin), placed at this origin in level blocks (x | y << 16); a
    // coarse level's window is the whole level (origin 0).
    uint window[SHADEL_MAX_MIPS];
    // Preserved layers across a window move: where the level's rect and window were last frame
    // (rect origin x | y << 16 and size w | h << 16 in sheet blocks, window origin in level
    // blocks x | y << 16); this frame's when the level stayed in place (prevBlockIndex).
    uint prevRectOrigin[SHADEL_MAX_MIPS];
    uint prevRectSize[SHADEL_MAX_MIPS];
    uint prevWindow[SHADEL_MAX_MIPS];
};

// 3-D debug lines (render/debug/debug_lines.h, shaders/debug/debug_lines.glsl): shaders append
// world-space segments, drawn over the frame before tonemapping (--debug-lines KIND,...).
#define DEBUG_LINES_LIGHTS 1u   // light ranges (spheres), spot cones, tube segments
#define DEBUG_LINES_BLOCKERS 2u // blocker rectangles, their portals, their shadow frusta per light
#define DEBUG_LINES_CHUNKS 4u   // world boxes of the shadel chunks shaded this frame
struct GpuDebugLine {
    vec3 a;
    uint colorA; // RGBA8 (packUnorm4x8)
    vec3 b;
    uint colorB;
};
// Header of the line buffer; GpuDebugLine[capacity] follow it.
struct GpuDebugLines {
    uint vertexCount; // VkDrawIndirectCommand, written from `count` before the draw
    uint instanceCount;
    uint firstVertex;
    uint firstInstance;
    uint count; // segments appended this frame (beyond capacity: counted, dropped)
    uint capacity;
    uint mask; // DEBUG_LINES_* kinds asked for
    uint pad;
};

// sizeof(GpuShadelObject) in the scalar layout: shaders address one object in place
// (ShadelObjectRef); static_assert'ed on the C++ side.
#define GPU_SHADEL_OBJECT_BYTES (40u + 36u * SHADEL_MAX_MIPS)

// One rectangle of the sheet in use this frame (the clear and allocation passes walk these).
struct GpuShadelRect {
    uvec4 rect; // x, y, w, h in blocks
    uint object;
    uint mip;
    uint firstBlock; // prefix sum of w*h over the rect list
    uint pad;
};

// One chunk of shading work: {chunk, storage slot, object, MIP}.
struct GpuShadelWork {
    uint chunk; // sheet chunk coordinate, x | y << 16
    uint slot;  // storage chunk slot
    uint object;
    uint mip;
};

// Why a marked chunk is shaded rather than carried over (GpuShadelCounters::shadedBecause).
#define SHADEL_SHADED_NOT_REUSABLE                                                                 \
    0u                               // reuse off; the object is new, or its level or inputs changed
#define SHADEL_SHADED_NEW 1u         // last frame did not store the chunk
#define SHADEL_SHADED_REFRESH 2u     // stored, but its turn to be refreshed
#define SHADEL_SHADED_NEAR_CHANGE 3u // a changed region meets the object: shading decides
#define SHADEL_SHADED_RT_HISTORY 4u  // the RT cache under it gained sqrt 2 x rays
#define SHADEL_SHADED_VIEW 5u        // the view turned past what its specular tolerates
#define SHADEL_SHADED_REASONS 6
// ShadelFrame::chunkReasons of a chunk carried over from last frame's storage.
#define SHADEL_CHUNK_CARRIED 0xFFu

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
    uint classCount[SHADE_CLASSES];    // entries in each shading class's list
    uint nearChangeCount;              // entries in the near-change list (SHADE_NEAR_CHANGE_LIST)
    uint magnifiedPixels;     // sampled reconstructed pixels whose MIP-0 shadel spans > 1 pixel
    uint reconstructedPixels; // sampled (even x and y) pixels the reconstruction drew
    uint chunksPerMip[SHADEL_MAX_MIPS]; // allocated chunks by MIP level
    // Sampled reconstructed pixels read from a coarser level than they wanted because that
    // level's window (last frame's marks + margin) did not hold them yet.
    uint windowFallbackPixels;
    // ... of those, the ones whose window lagged so far that they were shaded forward
    // (SHADEL_MAX_WINDOW_FALLBACK, shaders/shadel/shadel.glsl).
    uint windowForwardPixels;
    // Compute marking's listed quads (shaders/shadel/mark_quad.glsl): those its first pass left
    // to the two-triangle pass, and those left to the per-pixel pass (by the first pass or by
    // the two-triangle pass, where the triangles' levels differ).
    uint markQuadsTwoTriangles;
    uint markQuadsPerPixel;
    // Chunks queued for shading, by why they could not be carried over (SHADEL_SHADED_*).
    uint shadedBecause[SHADEL_SHADED_REASONS];
    uvec4 fillDispatch;  // x, y, z, marked blocks in the list: indirect args of the queue fill
    uvec4 shadeDispatch; // x, y, z, queue length: indirect args of the shading pass
    uvec4 copyDispatch;  // x, y, z, queue length: indirect args of the carry-over pass
    uvec4 classDispatch[SHADE_CLASSES]; // x, y, z, list length: each class's shading
    // x, y, z, list length: the near-change pass, one invocation per entry, 64 a workgroup
    uvec4 nearChangeDispatch;
    // x, y, z, queue length: one invocation per queued chunk, 64 a workgroup (passes that take a
    // chunk in one invocation: the spectra's chunk classify)
    uvec4 invocationDispatch;
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
    // uint[SHADE_CLASSES + 1][capacityChunks]: the shading queue's entries by shading class,
    // then the near-change list (SHADE_NEAR_CHANGE_LIST).
    uint64_t classQueues;
    uint64_t idMaps;    // uint16 triangle ids, packed in uints
    uint64_t shadelUvs; // vec2 per vertex of the unified geometry buffer
    // The shade storage's layers, chunk-linear buffers (shaders/shadel/shadel.glsl storageIndex:
    // shadel (x, y) of the chunk in slot s is element s * 64 + y * 8 + x): radiance uvec2 (RGBA16F
    // halves), material uint (RGBA8 unorm). This frame's, and last frame's for preserved layers.
    uint64_t layers[SHADEL_LAYERS];
    uint64_t prevLayers[SHADEL_LAYERS];
    uint sheetBlocks; // blocks per side of the virtual sheet
    uint rectCount;
    uint rectBlockCount;
    uint pad0;              // the 64-bit fields below stay 8-byte aligned in C++ and GLSL
    uint64_t prevOccupancy; // last frame's occupancy masks
    uint64_t prevOffsetMap; // last frame's offset map
    // Reuse: per storage slot, where its chunk was seen from when shaded (carried over with it):
    // uvec4 {a point of the chunk's surface (float bits; shaders/shadel/shade_chunk.glsl
    // chunkSurfacePoint), the unit direction from it to the camera (octahedral,
    // packSnorm2x16)}; x = SHADEL_CHUNK_VIEW_NONE: no shadel of it is covered.
    uint64_t chunkViews;
    uint64_t prevChunkViews; // last frame's
    // --visualize reuse only (else 0): uint per storage slot, why its chunk was shaded this frame
    // (SHADEL_SHADED_*) or SHADEL_CHUNK_CARRIED.
    uint64_t chunkReasons;
    // Regions whose lighting changed since last frame (render/shadel/reuse_invalidation.h):
    // capsules, two vec4s each: (a, radius), (b, 0); infinite radius = everywhere.
    uint64_t changedVolumes;
    // uvec4 per rect: the level blocks this frame's samples wanted, in window or not
    // {0xFFFF - min x, 0xFFFF - min y, max x + 1, max y + 1} (atomicMax; 0 = none), read back
    // to place next frame's windows.
    uint64_t levelWants;
    uint changedVolumeCount;
    uint frameNumber;   // frames rendered by this renderer (refresh phase)
    uint reuse;         // 0: reshade everything (--reuse off)
    uint refreshPeriod; // frames a carried-over chunk may go unshaded (--reuse-refresh)
    uint capacityChunks;
    uint markedCapacity;     // entries of markedBlocks (= capacityChunks: a block needs >= 1 chunk)
    uint allocationCounters; // hashed counters in use (SHADEL_COUNTERS; fewer only for tests)
    float shadingBias;
    float trilinearBand;  // width of the LOD interval blended between two MIPs (1 = trilinear)
    uint materialSamples; // material evaluations per shadel above MIP 0 (1 or 4)
    uint regionStart[SHADEL_MAX_MIPS]; // first block column of each MIP's region
};

// ---- Projected box decals (render/decals, shaders/decals) -----------------------------------
// Decal stages, applied in this order to the material before lighting (the AO-only kind darkens
// only ambient light, a character's contact shadow). A decal may take part in several.
#define DECAL_STAGE_BASE_COLOR 0u
#define DECAL_STAGE_NORMAL 1u
#define DECAL_STAGE_ROUGHNESS 2u
#define DECAL_STAGE_AMBIENT_OCCLUSION 3u // darkens ambient / indirect light only
#define DECAL_STAGES 4u
#define DECAL_KIND(stage) (1u << (stage))
// Procedural masks in the decal's [0,1]^2 projection (shaders/decals/decals.glsl).
#define DECAL_PATTERN_SPLAT 0u       // a soft-edged ring and disc (graffiti)
#define DECAL_PATTERN_STRIPES 1u     // diagonal stripes (road marking)
#define DECAL_PATTERN_RIVETS 2u      // a grid of round bumps (height for the normal stage)
#define DECAL_PATTERN_PUDDLE 3u      // a wobbly blob (wet patch: low roughness)
#define DECAL_PATTERN_BLOB 4u        // radial falloff (contact shadow under a character)
#define DECAL_TILE_MAX 256u          // decals one tile's / chunk's list holds
#define DECAL_OBJECT_ALL 0xFFFFFFFFu // an object list that did not fit: every frustum decal

struct GpuDecal {
    mat4 worldToBox; // world -> box space [-0.5, 0.5]^3; the box's z projects (faces the surface)
    vec3 center;     // world-space box: centre, unit axes, half sizes (culling, normal stage)
    uint kinds;      // DECAL_KIND(stage) bits
    vec3 axisX;
    uint pattern; // DECAL_PATTERN_*
    vec3 axisY;
    float normalStrength; // normal stage: height gradient scale
    vec3 axisZ;
    float roughness; // roughness stage: the target perceptual roughness
    vec3 halfSize;
    float occlusion; // AO stage: ambient kept at the mask's centre is 1 - occlusion
    vec4 color;      // base colour stage: rgb, a = opacity
};

// What decal culling shares with shading (FrameConstants::decals).
struct DecalFrame {
    uint64_t decals;        // GpuDecal[]
    uint64_t frustumDecals; // uint decal indices meeting the camera frustum, in decal order
    uint64_t tileRanges;    // uvec2 (first entry, count) per (tile * DECAL_STAGES + stage)
    uint64_t objectRanges;  // uvec2 (first entry, count) per instance: the decals its world
                            // bounds meet, in decal order (count DECAL_OBJECT_ALL: the list did
                            // not fit, take every frustum decal); shadel shading narrows them
                            // to each shadel's point
    uint64_t entries;       // the pool of uint decal indices both lists take room in
    uint64_t counters;      // DecalCounters
    uint64_t visibleDecals; // uint bit set: decals in at least one list
    uint frustumDecalCount;
    uint poolCapacity;
    uint tilesX;
    uint tilesY;
    uint instanceCount; // instances objectRanges holds (0 in forward mode)
    uint pad0;
};

struct DecalCounters {
    uint tilePairs;       // (decal, tile) pairs in the forward lists
    uint shadelPairs;     // (decal, shadel) pairs the shadel path's shading kept
    uint poolEntries;     // entries asked of the pool (every stage)
    uint listsOverflowed; // tiles or chunks whose lists did not fit (decals dropped)
    uint objectPairs;     // (decal, instance) pairs of the coarse per-object lists
};

#ifdef __cplusplus
} // namespace shadel::gpu
#endif
#endif
