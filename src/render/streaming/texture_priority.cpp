#include "render/streaming/texture_priority.h"

#include <algorithm>
#include <cmath>

namespace shadel {

std::vector<TextureUse> textureUses(const Scene& scene) {
    // UV units per metre per mesh (object space): sqrt of UV area over surface area.
    std::vector<float> meshUvPerMetre(scene.meshes.size(), 0.0f);
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        double uvArea = 0.0, area = 0.0;
        for (size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
            const Vertex& a = mesh.vertices[mesh.indices[i]];
            const Vertex& b = mesh.vertices[mesh.indices[i + 1]];
            const Vertex& c = mesh.vertices[mesh.indices[i + 2]];
            area += 0.5 * glm::length(glm::cross(b.position - a.position, c.position - a.position));
            glm::vec2 e1 = b.uv0 - a.uv0, e2 = c.uv0 - a.uv0;
            uvArea += 0.5 * std::abs(double(e1.x) * e2.y - double(e1.y) * e2.x);
        }
        meshUvPerMetre[m] = area > 0.0 ? float(std::sqrt(uvArea / area)) : 0.0f;
    }
    std::vector<TextureUse> uses;
    for (const Instance& inst : scene.instances) {
        if (inst.mesh >= scene.meshes.size()) continue;
        const Mesh& mesh = scene.meshes[inst.mesh];
        if (mesh.material >= scene.materials.size() || !mesh.bounds.valid()) continue;
        const Material& mat = scene.materials[mesh.material];
        Aabb world = transformAabb(mesh.bounds, inst.transform);
        float scale = std::cbrt(std::abs(glm::determinant(glm::mat3(inst.transform))));
        float uvPerMetre = scale > 0.0f ? meshUvPerMetre[inst.mesh] / scale : 0.0f;
        if (!(uvPerMetre > 0.0f)) continue;
        for (int32_t t :
             {mat.baseColorTexture, mat.metallicRoughnessTexture, mat.normalTexture,
              mat.emissiveTexture, mat.occlusionTexture, mat.clearcoatTexture,
              mat.clearcoatRoughnessTexture, mat.clearcoatNormalTexture, mat.specularTexture,
              mat.specularColorTexture, mat.sheenColorTexture, mat.sheenRoughnessTexture}) {
            if (t < 0 || size_t(t) >= scene.textures.size()) continue;
            uses.push_back(
                {uint32_t(t), world.center(), 0.5f * glm::length(world.extent()), uvPerMetre});
        }
    }
    return uses;
}

std::vector<float> cpuWantedSizes(const std::vector<TextureUse>& uses, size_t textureCount,
                                  const CameraView& camera, float viewportHeight) {
    std::vector<float> wanted(textureCount, 0.0f);
    auto planes = frustumPlanes(camera.proj * camera.view);
    float focalPixels = viewportHeight / (2.0f * std::tan(0.5f * camera.yfov));
    for (const TextureUse& u : uses) {
        bool inside = true;
        for (const glm::vec4& p : planes)
            if (glm::dot(glm::vec3(p), u.center) + p.w < -u.radius) inside = false;
        float distance = std::max(glm::length(u.center - camera.position) - u.radius, camera.znear);
        float pixelsPerMetre = focalPixels / distance;
        float side = pixelsPerMetre / u.uvPerMetre * (inside ? 1.0f : 0.25f);
        wanted[u.texture] = std::max(wanted[u.texture], side);
    }
    return wanted;
}

float mergedWanted(float cpuWanted, float gpuWanted, float cpuCap) {
    return std::max(gpuWanted, std::min(cpuWanted, cpuCap));
}

} // namespace shadel
