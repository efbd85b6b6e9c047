#include "render/streaming/texture_priority.h"

#include <algorithm>
#include <cmath>

namespace shadel {

std::vector<TextureUse> textureUses(const Scene& scene) {
    // UV units per metre per mesh and UV set (object space): sqrt of UV area over surface area.
    std::vector<glm::vec2> meshUvPerMetre(scene.meshes.size(), glm::vec2(0.0f));
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        double uvArea[2] = {0.0, 0.0}, area = 0.0;
        auto uvTriangleArea = [](glm::vec2 a, glm::vec2 b, glm::vec2 c) {
            glm::vec2 e1 = b - a, e2 = c - a;
            return 0.5 * std::abs(double(e1.x) * e2.y - double(e1.y) * e2.x);
        };
        for (size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
            const Vertex& a = mesh.vertices[mesh.indices[i]];
            const Vertex& b = mesh.vertices[mesh.indices[i + 1]];
            const Vertex& c = mesh.vertices[mesh.indices[i + 2]];
            area += 0.5 * glm::length(glm::cross(b.position - a.position, c.position - a.position));
            uvArea[0] += uvTriangleArea(a.uv0, b.uv0, c.uv0);
            uvArea[1] += uvTriangleArea(a.uv1, b.uv1, c.uv1);
        }
        for (int set = 0; set < 2; ++set)
            meshUvPerMetre[m][set] = area > 0.0 ? float(std::sqrt(uvArea[set] / area)) : 0.0f;
    }
    std::vector<TextureUse> uses;
    for (const Instance& inst : scene.instances) {
        if (inst.mesh >= scene.meshes.size()) continue;
        const Mesh& mesh = scene.meshes[inst.mesh];
        if (mesh.material >= scene.materials.size() || !mesh.bounds.valid()) continue;
        const Material& mat = scene.materials[mesh.material];
        Aabb world = transformAabb(mesh.bounds, inst.transform);
        float scale = std::cbrt(std::abs(glm::determinant(glm::mat3(inst.transform))));
        if (!(scale > 0.0f)) continue;
        // In TextureSlot order: each slot's footprint in the UV set it reads.
        const int32_t slots[kTextureSlotCount] = {
            mat.baseColorTexture,          mat.metallicRoughnessTexture, mat.normalTexture,
            mat.emissiveTexture,           mat.occlusionTexture,         mat.clearcoatTexture,
            mat.clearcoatRoughnessTexture, mat.clearcoatNormalTexture,   mat.specularTexture,
            mat.specularColorTexture,      mat.sheenColorTexture,        mat.sheenRoughnessTexture,
            mat.transmissionTexture,       mat.thicknessTexture};
        static_assert(kTextureSlotCount == 14, "one entry per TextureSlot, in its order");
        for (uint32_t slot = 0; slot < kTextureSlotCount; ++slot) {
            int32_t t = slots[slot];
            if (t < 0 || size_t(t) >= scene.textures.size()) continue;
            float uvPerMetre = meshUvPerMetre[inst.mesh][mat.texCoords[slot] == 1 ? 1 : 0] / scale;
            if (!(uvPerMetre > 0.0f)) continue;
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
