// GpuInstance::normalMatrix (render/normal_matrix.h): the inverse transpose of an instance's
// transform, and a finite matrix onto the flattened surface's normal where a scale of 0 leaves
// no inverse (an animation growing an object from nothing passes through it).
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "render/normal_matrix.h"

using namespace shadel;

namespace {
bool finite(const glm::mat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}
} // namespace

TEST(NormalMatrix, IsTheInverseTransposeOfAnInvertibleTransform) {
    glm::mat4 t = glm::translate(glm::mat4(1.0f), glm::vec3(3, -2, 5));
    t = glm::rotate(t, 0.7f, glm::normalize(glm::vec3(1, 2, 3)));
    for (glm::vec3 scale : {glm::vec3(1.0f), glm::vec3(2.0f, 0.5f, 3.0f), glm::vec3(-1, 1, 1),
                            glm::vec3(1e-3f, 4.0f, -2.0f)}) {
        glm::mat4 m = glm::scale(t, scale);
        glm::mat3 expected = glm::transpose(glm::inverse(glm::mat3(m)));
        glm::mat3 got(normalMatrixOf(m));
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r)
                EXPECT_NEAR(got[c][r], expected[c][r], 1e-3f * (1.0f + std::abs(expected[c][r])))
                    << "scale " << scale.x << " " << scale.y << " " << scale.z;
    }
}

TEST(NormalMatrix, FlattenedTransformGivesTheSurfaceNormal) {
    glm::mat4 rotation = glm::rotate(glm::mat4(1.0f), 0.4f, glm::vec3(0, 1, 0));
    glm::mat4 flat = glm::scale(rotation, glm::vec3(0.0f, 1.0f, 1.0f)); // squashed along local x
    glm::mat4 n = normalMatrixOf(flat);
    ASSERT_TRUE(finite(n)) << "the plain inverse is infinite here";
    // Every normal with a local-x part lands on the flattened plane's normal: local x rotated.
    glm::vec3 planeNormal = glm::vec3(rotation * glm::vec4(1, 0, 0, 0));
    glm::vec3 carried = glm::normalize(glm::mat3(n) * glm::normalize(glm::vec3(1, 1, 0)));
    EXPECT_NEAR(std::abs(glm::dot(carried, planeNormal)), 1.0f, 1e-5f);
    EXPECT_TRUE(finite(normalMatrixOf(glm::mat4(0.0f)))) << "scale 0 on every axis";
}
