#include "scene/scene.h"

namespace shadel {

Aabb transformAabb(const Aabb& box, const glm::mat4& m) {
    Aabb out;
    if (!box.valid()) return out;
    for (int i = 0; i < 8; ++i) {
        glm::vec3 corner{(i & 1) ? box.max.x : box.min.x, (i & 2) ? box.max.y : box.min.y,
                         (i & 4) ? box.max.z : box.min.z};
        out.extend(glm::vec3(m * glm::vec4(corner, 1.0f)));
    }
    return out;
}

Aabb Scene::worldBounds() const {
    Aabb out;
    for (const Instance& inst : instances)
        out.extend(transformAabb(meshes[inst.mesh].bounds, inst.transform));
    for (const PointLineSet& set : pointLines) // glTF points and lines
        for (const Vertex& v : set.vertices)
            out.extend(glm::vec3(set.transform * glm::vec4(v.position, 1.0f)));
    return out;
}

uint64_t Scene::triangleCount() const {
    uint64_t n = 0;
    for (const Instance& inst : instances) n += meshes[inst.mesh].triangleCount();
    return n;
}

} // namespace shadel
