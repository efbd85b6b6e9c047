// A spot light's bounds, written once for C++ (the light grid, the CPU frustum cull:
// render/lighting/light_grid.cpp) and GLSL (the tile and chunk culling:
// lighting/light_cull.glsl), so the grid lists a spot in the cells of the very sphere the GPU
// tests. Same conventions as common/shadel_bary.h: C++ gets namespace shadel::shader over glm.
#ifndef SHADEL_SPOT_BOUNDS_H
#define SHADEL_SPOT_BOUNDS_H

#ifdef __cplusplus
#include <glm/glm.hpp>

#include "common/shared_types.h"
#ifndef SHADEL_INLINE
#define SHADEL_INLINE inline
#endif
namespace shadel::shader {
using glm::clamp;
using glm::inversesqrt;
using glm::max;
using glm::sqrt;
using glm::vec2;
using glm::vec3;
using glm::vec4;
using uint = glm::uint;
#else
#ifndef SHADEL_INLINE
#define SHADEL_INLINE
#endif
#endif

// The cosine (x) and sine (y) of a spot's outer half angle, from its GpuLight spotOffset and
// spotScale (a square spot's: of the round cone around its square one). Gobos are spots.
SHADEL_INLINE vec2 spotConeCosSin(uint type, float spotOffset, float spotScale) {
    if (type == LIGHT_SPOT) {
        float c = clamp(-spotOffset / spotScale, -1.0f, 1.0f);
        return vec2(c, sqrt(1.0f - c * c));
    }
    float t = max(spotOffset / spotScale, 0.0f) * sqrt(2.0f);
    float c = inversesqrt(1.0f + t * t);
    return vec2(c, t * c);
}

// The smallest sphere around what a spot lights: the part of its range sphere (radius `reach`
// around `apex`) inside its cone (Wronski, "Cull that cone"): radius reach / (2 cos a) on the
// axis up to a 45-degree half angle, reach sin a beyond, the range sphere from 90 degrees on.
// Padded by 1e-4 of the reach: the sector's rim lies on the sphere. `direction` is unit.
SHADEL_INLINE vec4 spotSectorSphere(vec3 apex, vec3 direction, float reach, vec2 coneCosSin) {
    float c = coneCosSin.x, s = coneCosSin.y;
    if (c >= 0.70710678f) {
        float t = reach / (2.0f * c);
        return vec4(apex + direction * t, t + reach * 1e-4f);
    }
    if (c > 0.0f) return vec4(apex + direction * (reach * c), reach * s + reach * 1e-4f);
    return vec4(apex, reach);
}

#ifdef __cplusplus
} // namespace shadel::shader
#endif

#endif // SHADEL_SPOT_BOUNDS_H
