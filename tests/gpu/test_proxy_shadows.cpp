// Proxy (shadow) index sets (render/culling/mesh_lods.h): every LOD has a second index
// range over position-only deduplicated vertices, drawn by the shadow views.
#include <cstdio>

#include "gpu_test_env.h"
#include "render/culling/mesh_lods.h"
#include "scene/mesh_utils.h"

using namespace shadel;
using namespace shadel::test;

// A box's 24 vertices (4 per face, for the normals) are 8 positions: the proxy set draws the
// same triangles, position for position, over 8 vertices.
TEST(ProxyShadows, ProxySetHasTheSameTrianglesOverFewerVertices) {
    for (const Mesh& m : {makeBox("b", glm::vec3(1.0f), 0), makeSphere("s", 1.0f, 0, 24, 12)}) {
        MeshGeometry g;
        for (const Vertex& v : m.vertices)
            g.vertices.push_back({v.position, v.normal, v.tangent, v.uv0});
        g.indices = m.indices;
        std::vector<gpu::GpuVertex> vertices;
        std::vector<uint32_t> indices;
        gpu::GpuMeshLods lods = appendMeshWithLods(g, vertices, nullptr, indices);
        for (uint32_t k = 0; k < lods.lodCount; ++k) {
            const gpu::GpuLod& l = lods.lod[k];
            ASSERT_LE(size_t(l.proxyFirstIndex) + l.indexCount, indices.size());
            for (uint32_t i = 0; i < l.indexCount; ++i)
                ASSERT_EQ(vertices[indices[l.firstIndex + i]].position,
                          vertices[indices[l.proxyFirstIndex + i]].position);
            EXPECT_LT(l.proxyUniqueVertices, l.uniqueVertices) << m.name << " LOD " << k;
        }
        if (m.name == "b") {
            EXPECT_EQ(lods.lod[0].uniqueVertices, 24u);
            EXPECT_EQ(lods.lod[0].proxyUniqueVertices, 8u);
        }
    }
}

// The sun's shadow drawn from the proxy sets looks the same and fetches fewer vertices.
TEST(ProxyShadows, ShadowsMatchTheMainSetWithFewerVertices) {
    RenderOptions o = renderOptions("builtin:default", RenderMode::Forward, 192, 108);
    o.progress = false;
    RenderRun proxy = renderChecked(o);
    o.proxyShadows = false;
    RenderRun main = renderChecked(o);
    const auto& sp = proxy.stats["culling"]["views"]["shadow"];
    const auto& sm = main.stats["culling"]["views"]["shadow"];
    double p = psnr(proxy.frames[0].rgba, main.frames[0].rgba);
    std::printf("[ figures ] builtin:default 192x108 sun shadow view: vertices %u (main sets) -> "
                "%u (proxy sets), triangles %u -> %u, PSNR %.2f dB\n",
                sm["vertices_drawn"].get<uint32_t>(), sp["vertices_drawn"].get<uint32_t>(),
                sm["triangles_drawn"].get<uint32_t>(), sp["triangles_drawn"].get<uint32_t>(), p);
    EXPECT_GE(p, 35.0);
    EXPECT_EQ(sp["triangles_drawn"], sm["triangles_drawn"]);
    EXPECT_LT(sp["vertices_drawn"].get<uint32_t>(), sm["vertices_drawn"].get<uint32_t>());
    EXPECT_EQ(proxy.stats["culling"]["views"]["camera"]["vertices_drawn"],
              main.stats["culling"]["views"]["camera"]["vertices_drawn"])
        << "the camera keeps the main sets";
}
