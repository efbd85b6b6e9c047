#pragma once
// A GPU particle emitter as scenes describe it (render/particles simulates and draws it).
// Plain data: where particles are born, how they move, how they look over their life.
#include <cstdint>
#include <string>

#include <glm/glm.hpp>

namespace shadel {

struct ParticleEmitter {
    std::string name;
    glm::vec3 position{0.0f};
    float spawnRadius = 0.1f;     // births spread over a disc (xz) of this radius
    glm::vec3 velocity{0, 1, 0};  // m/s at birth
    float velocitySpread = 0.1f;  // +- per axis
    glm::vec3 acceleration{0.0f}; // buoyancy (up) or gravity (down)
    float drag = 0.5f;            // 1/s
    float turbulence = 0.0f;      // m/s^2 of sideways swirl
    glm::vec4 colorStart{1.0f};   // rgb: albedo (lit) or emission (unlit); a: opacity
    glm::vec4 colorEnd{1.0f};
    float sizeStart = 0.3f, sizeEnd = 1.0f; // metres
    float lifetime = 3.0f;                  // seconds (each particle 0.8x to 1.2x)
    uint32_t particleCount = 64;            // alive at once, at most
    float additiveness = 0.0f;              // 0: alpha-blended (smoke), 1: additive (fire)
    bool lit = true;                        // shaded by the lights (else emissive)
    float lodBias = 0.0f;     // particle atlas LOD bias (negative: more texels per sprite)
    float wrap = 0.5f;        // wrap shading of lit particles (0 = Lambert)
    float normalScale = 1.0f; // strength of the sprite's normal map
    uint32_t seed = 1;
    // Mesh particles (meshes cannot be lit through the atlas, so they go forward): opaque boxes
    // drawn with the forward pass's depth, lit per pixel or (vertexLit) per vertex, with wrap.
    bool mesh = false;
    bool vertexLit = false;
    float bounce = -1.0f; // >= 0: bounce off the ground plane y = 0 keeping this much speed
};

} // namespace shadel
