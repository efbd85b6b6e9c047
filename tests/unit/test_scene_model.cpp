#include <gtest/gtest.h>

#include "scene/scene.h"

#include <glm/gtc/matrix_transform.hpp>

using namespace shadel;

TEST(SceneModel, TransformAabbContainsTransformedCorners) {
    Aabb box;
    box.extend({-1, -2, -3});
    box.extend({1, 2, 3});
    glm::mat4 m = glm::rotate(glm::translate(glm::mat4(1), {10, 0, 0}), 0.7f, {0, 1, 0});
    Aabb out = transformAabb(box, m);
    for (int i = 0; i < 8; ++i) {
        glm::vec3 c{(i & 1) ? 1 : -1, (i & 2) ? 2 : -2, (i & 4) ? 3 : -3};
        glm::vec3 p = glm::vec3(m * glm::vec4(c, 1));
        EXPECT_TRUE(glm::all(glm::greaterThanEqual(p, out.min - 1e-4f)));
        EXPECT_TRUE(glm::all(glm::lessThanEqual(p, out.max + 1e-4f)));
    }
    EXPECT_FALSE(transformAabb(Aabb{}, m).valid());
}
