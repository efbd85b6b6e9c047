#pragma once
// The matrix that carries an instance's normals to world space (GpuInstance::normalMatrix, upper
// 3x3 used): the inverse transpose of its transform. A transform that flattens the object (a
// scale of 0 on an axis: animations that grow an object from nothing pass through it) has no
// inverse; there the cofactor matrix, which is det x inverse transpose wherever the inverse
// exists, still carries every normal onto the flattened surface's normal, and the shaders
// normalise what it gives.
#include <cmath>

#include <glm/glm.hpp>

namespace shadel {

inline glm::mat4 normalMatrixOf(const glm::mat4& transform) {
    glm::mat3 m(transform);
    float det = glm::determinant(m);
    glm::mat3 cofactor(glm::cross(m[1], m[2]), glm::cross(m[2], m[0]), glm::cross(m[0], m[1]));
    if (std::abs(det) > 1e-30f && std::isfinite(det)) return glm::mat4(cofactor / det);
    return glm::mat4(cofactor); // flattened: the surface's normal (up to sign)
}

} // namespace shadel
