#pragma once
// A projected box decal: whatever opaque surface lies inside the box takes
// the decal's contribution to its material before lighting (render/decals). The box's local z
// axis is the projection direction; the decal's pattern lies in its x/y face.
#include <cstdint>

#include <glm/glm.hpp>

namespace shadel {

enum class DecalPattern : uint32_t { Splat = 0, Stripes = 1, Rivets = 2, Puddle = 3, Blob = 4 };

struct Decal {
    glm::vec3 center{0.0f};
    glm::vec3 axisX{1, 0, 0}; // unit, the pattern's u direction
    glm::vec3 axisZ{0, 1, 0}; // unit, out of the surface it projects onto (y = cross(z, x))
    glm::vec3 size{1.0f};     // full extent along x, y, z
    // Stages it takes part in: DECAL_KIND(DECAL_STAGE_*) bits (common/shared_types.h).
    uint32_t kinds = 1;
    DecalPattern pattern = DecalPattern::Splat;
    glm::vec4 color{1.0f};       // base colour stage: rgb, a = opacity
    float roughness = 0.1f;      // roughness stage: target perceptual roughness
    float normalStrength = 1.0f; // normal stage: how steep the pattern's bumps are
    float occlusion = 0.7f;      // AO stage: share of ambient removed at the mask's centre
};

} // namespace shadel
