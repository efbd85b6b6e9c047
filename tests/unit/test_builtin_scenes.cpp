// Built-in scenes and the procedural meshes they are made of: deterministic, valid, with the
// content the renderer tests rely on; and mesh splitting for 16-bit triangle IDs.
#include <gtest/gtest.h>

#include <cstring>
#include <set>

#include "core/error.h"
#include "scene/builtin_scenes.h"
#include "scene/load.h"
#include "scene/mesh_utils.h"

using namespace shadel;

namespace {

// FNV-1a over every plain value of the scene: two scenes with the same hash are the same scene.
class SceneHasher {
public:
    uint64_t hash(const Scene& s) {
        add(s.name);
        for (const Mesh& m : s.meshes) {
            add(m.name);
            addBytes(m.vertices.data(), m.vertices.size() * sizeof(Vertex));
            addBytes(m.indices.data(), m.indices.size() * sizeof(uint32_t));
            addPod(m.material);
        }
        for (const Material& m : s.materials) {
            add(m.name);
            addPod(m.baseColorFactor), addPod(m.emissiveFactor), addPod(m.metallicFactor);
            addPod(m.roughnessFactor), addPod(m.procedural), addPod(m.proceduralScale),
                addPod(m.alphaMode);
        }
        for (const Instance& i : s.instances) add(i.name), addPod(i.mesh), addPod(i.transform);
        for (const Light& l : s.lights)
            add(l.name), addPod(l.type), addPod(l.position), addPod(l.direction),
                addPod(l.intensity);
        for (const Camera& c : s.cameras)
            add(c.name), addPod(c.position), addPod(c.forward), addPod(c.up);
        return h_;
    }

private:
    uint64_t h_ = 1469598103934665603ull;
    void addBytes(const void* p, size_t n) {
        for (size_t i = 0; i < n; ++i)
            h_ = (h_ ^ static_cast<const uint8_t*>(p)[i]) * 1099511628211ull;
    }
    template <typename T>
    void addPod(const T& v) {
        addBytes(&v, sizeof(T));
    }
    void add(const std::string& s) { addBytes(s.data(), s.size() + 1); }
};

uint64_t sceneHash(const Scene& s) {
    return SceneHasher().hash(s);
}

// Every triangle is CCW seen from the side its vertex normals point to, and (for the closed,
// convex-per-part procedural shapes and planes) normals point away from the mesh centre.
void expectOutwardCcw(const Mesh& mesh) {
    glm::vec3 centre = mesh.bounds.center();
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
        const Vertex& a = mesh.vertices[mesh.indices[t * 3]];
        const Vertex& b = mesh.vertices[mesh.indices[t * 3 + 1]];
        const Vertex& c = mesh.vertices[mesh.indices[t * 3 + 2]];
        glm::vec3 geometric = glm::cross(b.position - a.position, c.position - a.position);
        ASSERT_GT(glm::length(geometric), 0.0f)
            << mesh.name << " triangle " << t << " is degenerate";
        ASSERT_GT(glm::dot(geometric, a.normal + b.normal + c.normal), 0.0f)
            << mesh.name << " triangle " << t;
    }
    for (const Vertex& v : mesh.vertices)
        ASSERT_GE(glm::dot(v.normal, v.position - centre), -1e-4f)
            << mesh.name << " normal points inwards";
}

// Tangents follow the UV gradient: d(position)/du projected on the tangent plane; bitangents
// point along -d(position)/dv, toward the texture's top (a glTF normal map's +Y).
void expectTangentsFollowU(const Mesh& mesh) {
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
        const Vertex* v[3] = {&mesh.vertices[mesh.indices[t * 3]],
                              &mesh.vertices[mesh.indices[t * 3 + 1]],
                              &mesh.vertices[mesh.indices[t * 3 + 2]]};
        glm::vec3 e1 = v[1]->position - v[0]->position, e2 = v[2]->position - v[0]->position;
        glm::vec2 d1 = v[1]->uv0 - v[0]->uv0, d2 = v[2]->uv0 - v[0]->uv0;
        float det = d1.x * d2.y - d2.x * d1.y;
        if (std::abs(det) < 1e-8f) continue;
        glm::vec3 dPdu = (e1 * d2.y - e2 * d1.y) / det;
        glm::vec3 dPdv = (e2 * d1.x - e1 * d2.x) / det;
        for (const Vertex* vert : v) {
            EXPECT_GT(glm::dot(glm::vec3(vert->tangent), dPdu), 0.0f)
                << mesh.name << " triangle " << t;
            glm::vec3 bitangent =
                glm::cross(vert->normal, glm::vec3(vert->tangent)) * vert->tangent.w;
            EXPECT_LT(glm::dot(bitangent, dPdv), 0.0f) << mesh.name << " triangle " << t;
        }
    }
}

} // namespace

// --- procedural meshes --------------------------------------------------------------------

TEST(ProceduralMeshes, BoxPlaneSphereCylinderAreOutwardCcwWithTangents) {
    std::vector<Mesh> meshes = {
        makeBox("box", {2.0f, 1.0f, 0.5f}, 0),
        makePlane("plane", 4.0f, 3.0f, 0, 3),
        makeSphere("sphere", 0.7f, 0, 24, 12),
        makeCylinder("cylinder", 0.4f, 2.0f, 0, 16),
    };
    Scene scene;
    scene.materials.emplace_back();
    for (Mesh& m : meshes) {
        expectOutwardCcw(m);
        expectTangentsFollowU(m);
        scene.meshes.push_back(m);
    }
    EXPECT_EQ(sceneInvariantViolation(scene), "");
    EXPECT_EQ(meshes[0].triangleCount(), 12u);
    EXPECT_EQ(meshes[1].triangleCount(), 18u);
    EXPECT_NEAR(glm::distance(meshes[0].bounds.max, glm::vec3(1.0f, 0.5f, 0.25f)), 0.0f, 1e-6f);
    EXPECT_NEAR(meshes[2].bounds.max.y, 0.7f, 1e-5f);
    EXPECT_NEAR(meshes[3].bounds.max.y, 2.0f, 1e-6f);
    EXPECT_NEAR(meshes[3].bounds.min.y, 0.0f, 1e-6f);
}

TEST(ProceduralMeshes, PlaneUvIsWorldMetres) {
    Mesh plane = makePlane("plane", 10.0f, 6.0f, 0, 2);
    for (const Vertex& v : plane.vertices) {
        EXPECT_FLOAT_EQ(v.uv0.x, v.position.x);
        EXPECT_FLOAT_EQ(v.uv0.y, -v.position.z);
    }
}

TEST(MeshUtils, ComputedNormalsAndTangentsAreUnitAndRepairHandlesGarbage) {
    Mesh m = makeBox("box", glm::vec3(1.0f), 0);
    m.vertices[0].normal = glm::vec3(NAN);
    m.vertices[1].normal = glm::vec3(0.0f);
    m.vertices[2].tangent = glm::vec4(INFINITY);
    m.vertices[3].uv0 = glm::vec2(NAN);
    EXPECT_EQ(sanitizeNormalsAndTangents(m), 4u);
    Scene scene;
    scene.materials.emplace_back();
    scene.meshes.push_back(m);
    EXPECT_EQ(sceneInvariantViolation(scene), "");
    // The repaired normal comes from the geometry (the +X face's vertices).
    EXPECT_GT(m.vertices[0].normal.x, 0.5f);
}

TEST(MeshUtils, SplitKeepsTrianglesInOrderAndCompactsVertices) {
    Mesh grid = makePlane("grid", 10.0f, 10.0f, 3, 200); // 80 000 triangles
    ASSERT_EQ(grid.triangleCount(), 80000u);
    std::vector<Mesh> parts = splitMesh(grid);
    ASSERT_EQ(parts.size(), 2u);
    uint64_t total = 0;
    size_t t = 0;
    for (const Mesh& part : parts) {
        EXPECT_LE(part.triangleCount(), kMaxTrianglesPerMesh);
        EXPECT_EQ(part.material, 3u);
        total += part.triangleCount();
        std::vector<bool> used(part.vertices.size(), false);
        for (size_t i = 0; i < part.indices.size(); ++i, ++t) {
            used[part.indices[i]] = true;
            const Vertex& a = part.vertices[part.indices[i]];
            const Vertex& b = grid.vertices[grid.indices[t]];
            ASSERT_EQ(std::memcmp(&a, &b, sizeof(Vertex)), 0) << "index " << t;
        }
        for (bool u : used) EXPECT_TRUE(u) << "unused vertex in part " << part.name;
    }
    EXPECT_EQ(total, 80000u);
    EXPECT_EQ(parts[0].triangleCount(), 65535u);

    // Exact multiples and small meshes.
    EXPECT_EQ(splitMesh(makeBox("b", glm::vec3(1), 0)).size(), 1u);
    std::vector<Mesh> thirds = splitMesh(grid, 40000);
    ASSERT_EQ(thirds.size(), 2u);
    EXPECT_EQ(thirds[1].triangleCount(), 40000u);
}

// --- built-in scenes ----------------------------------------------------------------------

TEST(BuiltinScenes, NamesAndUnknownName) {
    std::vector<std::string> names = builtinSceneNames();
    ASSERT_GE(names.size(), 3u);
    EXPECT_EQ(names[0], "default");
    for (const char* required : {"default", "checker", "smooth"})
        EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
    try {
        loadScene("builtin:nope");
        FAIL() << "no error for an unknown built-in scene";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("builtin:nope: ", 0), 0u) << e.what();
    }
}

TEST(BuiltinScenes, AllAreDeterministicAndValid) {
    for (const std::string& name : builtinSceneNames()) {
        Scene a = loadScene("builtin:" + name);
        Scene b = loadScene("builtin:" + name);
        EXPECT_EQ(sceneHash(a), sceneHash(b)) << name;
        EXPECT_EQ(sceneInvariantViolation(a), "") << name;
        EXPECT_EQ(a.name, name);
        EXPECT_GT(a.triangleCount(), 0u);
        ASSERT_FALSE(a.cameras.empty()) << name;
        EXPECT_EQ(a.cameras[0].name, "main") << name;
        std::set<std::string> cameraNames;
        for (const Camera& c : a.cameras)
            EXPECT_TRUE(cameraNames.insert(c.name).second) << name << " " << c.name;
        int suns = 0;
        for (const Light& l : a.lights)
            suns += (l.type == LightType::Directional && l.castsShadow) ? 1 : 0;
        EXPECT_EQ(suns, 1) << name;
        for (const Mesh& m : a.meshes) expectOutwardCcw(m);
        // Every mesh is used and every instance sits on or above the ground plane (y >= 0), but
        // for foundations: builtin:many's buildings are sunk 10 cm so that their bottom faces
        // are not coplanar with the ground (z-fighting, acne).
        constexpr float kFoundation = 0.1f;
        std::vector<bool> used(a.meshes.size(), false);
        for (const Instance& i : a.instances) {
            used[i.mesh] = true;
            EXPECT_GE(transformAabb(a.meshes[i.mesh].bounds, i.transform).min.y,
                      -kFoundation - 1e-4f)
                << name << " " << i.name;
        }
        for (size_t m = 0; m < used.size(); ++m)
            EXPECT_TRUE(used[m]) << name << " mesh " << a.meshes[m].name;
        // No camera starts inside an object (or below the ground).
        for (const Camera& c : a.cameras) {
            EXPECT_GT(c.position.y, 0.2f) << name << " camera " << c.name;
            for (const Instance& i : a.instances) {
                Aabb box = transformAabb(a.meshes[i.mesh].bounds, i.transform);
                bool inside = glm::all(glm::greaterThan(c.position, box.min - c.znear)) &&
                              glm::all(glm::lessThan(c.position, box.max + c.znear));
                EXPECT_FALSE(inside) << name << " camera " << c.name << " is inside " << i.name;
            }
        }
    }
}

TEST(BuiltinScenes, DefaultHasVariedObjectsCheckerSunAndLocalLights) {
    Scene s = loadScene("builtin:default");
    EXPECT_GE(s.instances.size(), 200u);
    EXPECT_LE(s.instances.size(), 1000u);
    float largest = 0.0f, smallest = 1e30f;
    for (const Instance& i : s.instances) {
        float size = glm::length(transformAabb(s.meshes[i.mesh].bounds, i.transform).extent());
        largest = std::max(largest, size), smallest = std::min(smallest, size);
    }
    EXPECT_GE(largest, 100.0f); // the ground
    EXPECT_LE(smallest, 0.06f); // objects of a few centimetres
    int checkerInstances = 0, brickInstances = 0;
    for (const Instance& i : s.instances) {
        Procedural p = s.materials[s.meshes[i.mesh].material].procedural;
        checkerInstances += p == Procedural::TexelChecker;
        brickInstances += p == Procedural::Bricks;
    }
    EXPECT_GE(checkerInstances, 2);
    EXPECT_GE(brickInstances, 3);
    int points = 0, spots = 0;
    for (const Light& l : s.lights)
        points += l.type == LightType::Point, spots += l.type == LightType::Spot;
    EXPECT_GE(points, 3);
    EXPECT_GE(spots, 2);
    EXPECT_GE(s.lights.size(), 6u);
    EXPECT_LE(s.lights.size(), 12u);
    EXPECT_GE(s.cameras.size(), 2u);
    Aabb world = s.worldBounds();
    EXPECT_NEAR(world.extent().x, 120.0f, 1.0f);
    EXPECT_NEAR(world.extent().z, 120.0f, 1.0f);
}

TEST(BuiltinScenes, CheckerIsAHugeTexelCheckerSeenAtAGrazingAngle) {
    Scene s = loadScene("builtin:checker");
    bool found = false;
    for (const Instance& i : s.instances) {
        const Mesh& m = s.meshes[i.mesh];
        const Material& mat = s.materials[m.material];
        if (mat.procedural != Procedural::TexelChecker) continue;
        found = true;
        EXPECT_GE(m.bounds.extent().x, 150.0f);
        EXPECT_GE(mat.proceduralScale, 10.0f); // cells of at most 10 cm (uv = metres)
    }
    EXPECT_TRUE(found);
    const Camera& cam = s.cameras[0];
    float degreesDown = glm::degrees(std::asin(-cam.forward.y));
    EXPECT_GT(degreesDown, 3.0f);
    EXPECT_LT(degreesDown, 12.0f);
    EXPECT_GT(cam.position.y, 0.5f);
    EXPECT_LT(cam.position.y, 5.0f);
}

TEST(BuiltinScenes, SmoothHasOnlyLowFrequencyMaterials) {
    Scene s = loadScene("builtin:smooth");
    for (const Material& m : s.materials) {
        EXPECT_EQ(m.procedural, Procedural::None) << m.name;
        EXPECT_EQ(m.baseColorTexture, kNoTexture) << m.name;
        EXPECT_EQ(m.normalTexture, kNoTexture) << m.name;
    }
    EXPECT_TRUE(s.textures.empty());
    EXPECT_GE(s.instances.size(), 5u);
    int points = 0;
    for (const Light& l : s.lights) points += l.type == LightType::Point;
    EXPECT_GE(points, 1);
}

TEST(BuiltinScenes, ManyHasTenThousandInstances) {
    Scene s = loadScene("builtin:many");
    EXPECT_GE(s.instances.size(), 10000u);
    EXPECT_LE(s.meshes.size(), 20u);
}
