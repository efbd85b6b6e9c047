// GPU particle layouts shared by C++ (render/particles) and GLSL (shaders/particles), scalar
// block layout on both sides. C++ includes this inside namespace shadel::gpu with glm types.
#ifndef SHADEL_PARTICLE_TYPES_H
#define SHADEL_PARTICLE_TYPES_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace shadel::gpu {
using glm::mat4;
using glm::uvec2;
using glm::vec2;
using glm::vec3;
using glm::vec4;
using uint = uint32_t;
#endif

#define PARTICLE_EMITTER_LIT 1u  // shaded with the scene's lights (smoke); else emissive (fire)
#define PARTICLE_EMITTER_MESH 2u // opaque mesh particles (forward path), not sprites
#define PARTICLE_EMITTER_VERTEX_LIT 4u // mesh particles lit per vertex (else per pixel)
#define PARTICLE_MESH_VERTICES 36u     // a mesh particle: a box, 12 triangles

// --particle-lighting: where a lit sprite's lighting is computed.
#define PARTICLE_LIGHTING_ATLAS 0u  // per atlas texel, once per frame
#define PARTICLE_LIGHTING_PIXEL 1u  // per pixel of every sprite layer (the reference)
#define PARTICLE_LIGHTING_VERTEX 2u // per sprite corner, interpolated

#define PARTICLE_NOT_SPAWNED 0xFFFFFFFFu // generation of a particle not yet born
#define PARTICLE_NO_ATLAS 0xFFFFFFFFu    // atlasEntry of a sprite without an atlas rect

// One emitter: where particles are born, how they move, and how they look over their life.
struct GpuParticleEmitter {
    vec3 position;
    float spawnRadius; // births are spread over a disc of this radius (xz)
    vec3 velocity;     // at birth
    float velocitySpread;
    vec3 acceleration; // buoyancy / gravity
    float drag;        // 1/s
    vec4 colorStart;   // rgb: albedo (lit) or emission (unlit); a: opacity
    vec4 colorEnd;
    float sizeStart; // metres
    float sizeEnd;
    float lifetime; // seconds
    float additiveness;
    uint firstParticle;
    uint particleCount;
    uint flags; // PARTICLE_EMITTER_*
    uint seed;
    float lodBias;     // artist bias of the atlas LOD (negative: more texels per sprite)
    float turbulence;  // m/s^2 of sideways swirl
    float wrap;        // wrap ("non-directional") shading: 0 = Lambert, 1 = fully wrapped
    float normalScale; // strength of the sprite's normal map
    float bounce;      // >= 0: particles bounce off the ground plane y = 0 keeping this much speed
};

// One particle: its simulated state (written by simulate.comp) and this frame's atlas entry.
struct GpuParticle {
    vec3 position;
    float age; // seconds; < 0: not born yet
    vec3 velocity;
    float lifetime;
    uint emitter;
    uint generation; // respawn count (seeds the sprite's look), PARTICLE_NOT_SPAWNED before birth
    float rotation;  // of the sprite in the camera plane
    uint atlasEntry; // lod << 24 | index among this frame's sprites of that LOD, or NO_ATLAS
};

// Per frame (host-visible), what every particle pass reads.
struct ParticleFrame {
    uint64_t particles;   // GpuParticle[]
    uint64_t emitters;    // GpuParticleEmitter[]
    uint64_t atlasCounts; // ParticleAtlasCounts
    uint particleCount;
    uint steps;    // simulation steps this frame (prewarm on the first)
    float dt;      // seconds per step
    float time;    // simulated seconds before this frame
    uint lighting; // PARTICLE_LIGHTING_*
    uint atlasSize;
    uint atlasWriteSlot; // bindless storage image (rgba16f)
    uint atlasReadSlot;  // bindless sampled texture
    // Half-resolution sprites (--particle-resolution half): each fragment stands for a 2x2
    // block of full-resolution pixels and tests itself against their depths (sampled here).
    uint halfRes;
    uint depthReadSlot;
};

#ifdef __cplusplus
} // namespace shadel::gpu
#endif
#endif
