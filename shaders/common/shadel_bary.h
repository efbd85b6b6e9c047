// Shadel reconstruction math, written once for C++ (tests, baker) and GLSL (shading pass).
//
// GLSL: #extension GL_GOOGLE_include_directive : require, then #include "common/shadel_bary.h".
// C++:  #include "common/shadel_bary.h"; the functions live in namespace shadel::shader and use
//       glm's vec2/vec3/uvec2, so the same source compiles in both languages.
//
// Shadel coordinate convention (the GPU code uses exactly this):
//   An object's MIP-0 shadel rect is W x H shadels (BakedMesh::width/height, multiples of 8).
//   MIP k is (W >> k) x (H >> k). Shadel (x, y) at MIP k has its centre at
//       uv = ((x + 0.5) / (W >> k), (y + 0.5) / (H >> k))
//   in the object's shadel-UV space [0,1]^2 (BakedMesh::shadelUv). x grows with u, y grows with v;
//   ID maps are stored row-major, index y * (W >> k) + x, row 0 first.
//  Barycentrics of shadels outside their triangle: the two free coordinates are clamped to [-eps, 1
// + eps] and the third is 1 minus the others. Shadels near a triangle edge, and every shadel the
// ID-map flood pushed into the gutter, have centres outside their triangle; their barycentrics must
// extrapolate the triangle's plane so that the reconstruction filter, which blends them with
// shadels inside the triangle, sees a smooth continuation. Clamping to [0,1] would snap all of them
// onto the edge: every outside shadel then shades the same edge point and bilinear reconstruction
// shows a visible band along chart borders (the same artefact as centroid vs. non-centroid sampling
// with MSAA). The epsilon only bounds extrapolation on slivers, where one shadel of distance is
// many triangle heights and unbounded barycentrics would fling the position far off the surface.
#ifndef SHADEL_BARY_H
#define SHADEL_BARY_H

#ifdef __cplusplus
#include <glm/glm.hpp>
#define SHADEL_INLINE inline
#define SHADEL_CONST constexpr
namespace shadel::shader {
using glm::abs;
using glm::clamp;
using glm::max;
using glm::min;
using glm::uvec2;
using glm::vec2;
using glm::vec3;
using uint = glm::uint;
#else
#define SHADEL_INLINE
#define SHADEL_CONST const
#endif

// How far (in barycentric units) reconstruction may extrapolate beyond a triangle: 1.0. The
// ID-map flood places shadels at most ~2 shadels outside their triangle, which for
// any triangle wider than ~2 shadels stays well inside this bound and is therefore exact.
SHADEL_CONST float kShadelBaryEpsilon = 1.0f;
// Below this |2 * signed area| (in the units of the inputs) a triangle is treated as degenerate.
SHADEL_CONST float kShadelDegenerateArea = 1e-24f;

// Size of MIP `level` of an object whose MIP-0 shadel rect is mip0Size.
SHADEL_INLINE uvec2 shadelLevelSize(uvec2 mip0Size, uint level) {
    return max(mip0Size >> level, uvec2(1u));
}

// Centre of shadel `shadel` of a level of size levelSize, in shadel-UV space.
SHADEL_INLINE vec2 shadelCenterUv(uvec2 shadel, uvec2 levelSize) {
    return (vec2(shadel) + vec2(0.5f)) / vec2(levelSize);
}

// Barycentrics (weights of a, b, c) of p, with the b and c weights clamped to [-eps, 1 + eps].
// A degenerate triangle returns its centroid weights rather than NaN/Inf.
SHADEL_INLINE vec3 shadelBarycentrics(vec2 p, vec2 a, vec2 b, vec2 c) {
    vec2 ab = b - a;
    vec2 ac = c - a;
    vec2 ap = p - a;
    float den = ab.x * ac.y - ac.x * ab.y;
    if (abs(den) < kShadelDegenerateArea) return vec3(1.0f / 3.0f);
    float invDen = 1.0f / den;
    float wb =
        clamp((ap.x * ac.y - ac.x * ap.y) * invDen, -kShadelBaryEpsilon, 1.0f + kShadelBaryEpsilon);
    float wc =
        clamp((ab.x * ap.y - ap.x * ab.y) * invDen, -kShadelBaryEpsilon, 1.0f + kShadelBaryEpsilon);
    return vec3(1.0f - wb - wc, wb, wc);
}

// Barycentrics at a shadel's centre and at the centres one shadel right (+x) and one shadel
// down (+y) at the same level: attribute differences against `center` are the per-shadel
// derivatives the shading pass uses to pick texture MIPs.
struct ShadelBary {
    vec3 center;
    vec3 right;
    vec3 down;
};

SHADEL_INLINE ShadelBary shadelBaryWithNeighbours(uvec2 shadel, uvec2 levelSize, vec2 a, vec2 b,
                                                  vec2 c) {
    vec2 step = vec2(1.0f) / vec2(levelSize);
    vec2 p = shadelCenterUv(shadel, levelSize);
    ShadelBary r;
    r.center = shadelBarycentrics(p, a, b, c);
    r.right = shadelBarycentrics(p + vec2(step.x, 0.0f), a, b, c);
    r.down = shadelBarycentrics(p + vec2(0.0f, step.y), a, b, c);
    return r;
}

// A texture coordinate extrapolated from a triangle (a shadel outside it), kept within the box of
// the triangle's own coordinates a, b, c.
SHADEL_INLINE vec2 clampToTriangleUv(vec2 uv, vec2 a, vec2 b, vec2 c) {
    return clamp(uv, min(a, min(b, c)), max(a, max(b, c)));
}

SHADEL_INLINE vec3 shadelInterpolate(vec3 bary, vec3 a, vec3 b, vec3 c) {
    return a * bary.x + b * bary.y + c * bary.z;
}

SHADEL_INLINE vec2 shadelInterpolate2(vec3 bary, vec2 a, vec2 b, vec2 c) {
    return a * bary.x + b * bary.y + c * bary.z;
}

#ifdef __cplusplus
} // namespace shadel::shader
#endif

#endif // SHADEL_BARY_H
