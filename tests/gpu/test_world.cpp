// The GPU-driven world (render/culling): builtin:many at scale, per-view culling counts, LOD
// chains chosen on the GPU, two-phase hierarchical-Z occlusion culling.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <sys/wait.h>

#include <algorithm>

#include "gpu_test_env.h"
#include "render/camera.h"
#include "render/culling/instance_grid.h"
#include "render/culling/mesh_lods.h"
#include "scene/builtin_scenes.h"
#include "scene/mesh_utils.h"

using namespace shadel;
using namespace shadel::test;

namespace {

// builtin:many at w x h; an explicit density keeps the scene unsplit, so the GPU's instances
// are the scene's.
RenderOptions manyOptions(uint32_t instances, uint32_t w, uint32_t h) {
    RenderOptions o = renderOptions("builtin:many", RenderMode::Forward, w, h);
    o.instances = instances;
    o.shadelsPerMetre = 4.0f;
    o.progress = false;
    return o;
}

const nlohmann::json& view(const RenderRun& run, const char* name) {
    return run.stats["culling"]["views"][name];
}

int runShadel(const std::string& args, std::string& err) {
    std::string errFile = tempPath("world_stderr.txt");
    std::string cmd =
        std::string("timeout 120 ") + SHADEL_BINARY + " " + args + " >/dev/null 2>" + errFile;
    int status = std::system(cmd.c_str());
    std::ifstream in(errFile);
    std::stringstream ss;
    ss << in.rdbuf();
    err = ss.str();
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

} // namespace

TEST(World, ManyBuildsTheAskedInstanceCount) {
    for (uint32_t n : {1u, 17u, 1000u, 4321u}) {
        Scene s = makeBuiltinScene("many", {n});
        EXPECT_EQ(s.instances.size(), n);
    }
    EXPECT_EQ(makeBuiltinScene("many").instances.size(), kManyDefaultInstances);
    EXPECT_THROW(makeBuiltinScene("many", {kManyMaxInstances + 1}), InputError);
    EXPECT_THROW(makeBuiltinScene("default", {10}), InputError);
}

TEST(World, BadWorldFlagsAreOneLineAndExitCode2) {
    for (const std::string args :
         {"render --size 16x16 --scene builtin:many --instances 1000001",
          "render --size 16x16 --scene builtin:many --instances 0",
          "render --size 16x16 --scene builtin:many --instances -4",
          "render --size 16x16 --scene builtin:default --instances 10",
          "render --size 16x16 --lod maybe", "render --size 16x16 --occlusion 1",
          "render --size 16x16 --mode decoupled --marking visibility --occlusion on"}) {
        std::string err;
        EXPECT_EQ(runShadel(args, err), 2) << args << ": " << err;
        EXPECT_EQ(err.rfind("shadel: ", 0), 0u) << args << ": " << err;
        EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << args << ": " << err;
    }
}

// --lod-error: a larger projected error picks coarser LODs, so fewer triangles are drawn; the
// stats echo the value; a value out of range is one line and exit code 2.
TEST(World, LodErrorTradesTrianglesForSilhouetteError) {
    const float errors[] = {0.5f, 8.0f};
    uint64_t triangles[2] = {};
    for (int i = 0; i < 2; ++i) {
        RenderOptions o = manyOptions(3000, 160, 90);
        o.lod = true;
        o.lodErrorPixels = errors[i];
        RenderRun run = renderChecked(o);
        triangles[i] = run.stats["triangles_drawn"].get<uint64_t>();
        EXPECT_FLOAT_EQ(run.stats["settings"]["lod-error"].get<float>(), errors[i]);
    }
    std::printf("[ figures ] many 3000 at 160x90, --lod on: %llu triangles drawn at --lod-error "
                "0.5, %llu at 8\n",
                (unsigned long long)triangles[0], (unsigned long long)triangles[1]);
    EXPECT_LT(triangles[1], triangles[0]);
    std::string err;
    EXPECT_EQ(runShadel("render --size 16x16 --lod-error 0", err), 2) << err;
    EXPECT_NE(err.find("--lod-error 0"), std::string::npos) << err;
}

// The GPU's per-view counts against a CPU frustum test of the same boxes.
TEST(World, CameraAndShadowCountsMatchTheScene) {
    const uint32_t n = 3000, w = 160, h = 90;
    RenderOptions o = manyOptions(n, w, h);
    o.sunShadowCache = false; // the sun's list culled against the camera (see below)
    RenderRun run = renderChecked(o);
    const auto& s = run.stats;
    ASSERT_EQ(s["instances"].get<uint32_t>(), n);
    Scene scene = makeBuiltinScene("many", {n});
    CameraView cam = makeCameraView(findCamera(scene, ""), w, h);
    auto planes = frustumPlanes(cam.proj * cam.view);
    uint32_t inside = 0;
    uint64_t triangles = 0;
    for (const Instance& inst : scene.instances) {
        Aabb b = transformAabb(scene.meshes[inst.mesh].bounds, inst.transform);
        bool in = true;
        for (const glm::vec4& p : planes) {
            glm::vec3 far(p.x >= 0 ? b.max.x : b.min.x, p.y >= 0 ? b.max.y : b.min.y,
                          p.z >= 0 ? b.max.z : b.min.z);
            in = in && glm::dot(glm::vec3(p), far) + p.w >= 0.0f;
        }
        inside += in;
        if (in) triangles += scene.meshes[inst.mesh].indices.size() / 3;
    }
    const auto& camera = view(run, "camera");
    std::printf(
        "[ figures ] many %u at %ux%u: camera %u of %u drawn (CPU frustum: %u), shadow %u\n", n, w,
        h, camera["instances_drawn"].get<uint32_t>(), n, inside,
        view(run, "shadow")["instances_drawn"].get<uint32_t>());
    EXPECT_EQ(camera["frustum_visible"].get<uint32_t>(), inside);
    EXPECT_EQ(camera["instances_drawn"].get<uint32_t>(), inside) << "no LODs, no occlusion";
    EXPECT_EQ(camera["triangles_drawn"].get<uint64_t>(), triangles);
    EXPECT_EQ(s["instances_drawn"], camera["instances_drawn"]);
    EXPECT_LT(inside, n / 2) << "street-level camera: the frustum alone culls most of the city";
    // Shadow casters whose shadow cannot reach the view are culled; the rest are drawn (the
    // run keeps no sun map: a kept one holds every caster in the sun's volume).
    uint32_t shadow = view(run, "shadow")["instances_drawn"].get<uint32_t>();
    EXPECT_GT(shadow, 0u);
    EXPECT_LT(shadow, n);
}

// Every level indexes only LOD 0's vertices (the shadel UVs stay valid), fewer triangles a level,
// errors growing, the tessellated sphere reduced well.
TEST(World, LodChainsSimplifyWithinTheMeshVertices) {
    Mesh sphere = makeSphere("s", 1.0f, 0, 32, 16);
    MeshGeometry g;
    for (const Vertex& v : sphere.vertices)
        g.vertices.push_back({v.position, v.normal, v.tangent, v.uv0});
    for (size_t i = 0; i < g.vertices.size(); ++i) g.shadelUvs.push_back(glm::vec2(float(i), 0.5f));
    g.indices = sphere.indices;
    g.keepTriangleOrder = true;
    std::vector<gpu::GpuVertex> vertices(5); // something before it: offsets must hold
    std::vector<glm::vec2> uvs(5);
    std::vector<uint32_t> indices(9, 0);
    gpu::GpuMeshLods lods = appendMeshWithLods(g, vertices, &uvs, indices);
    ASSERT_GE(lods.lodCount, 3u);
    EXPECT_EQ(lods.lod[0].firstIndex, 9u);
    EXPECT_EQ(lods.lod[0].indexCount, sphere.indices.size());
    // LOD 0 keeps its triangle order (the ID maps index it), through the vertex reordering.
    for (size_t i = 0; i < sphere.indices.size(); ++i) {
        uint32_t v = indices[9 + i];
        ASSERT_EQ(uvs[5 + v].x, float(sphere.indices[i])) << "vertex and shadel UV moved apart";
        ASSERT_EQ(vertices[5 + v].position, sphere.vertices[sphere.indices[i]].position);
    }
    for (uint32_t k = 1; k < lods.lodCount; ++k) {
        EXPECT_LT(lods.lod[k].indexCount, lods.lod[k - 1].indexCount);
        EXPECT_GE(lods.lod[k].error, lods.lod[k - 1].error);
        EXPECT_LT(lods.lod[k].error, 1.0f) << "error bound, in the radius-1 sphere's units";
        for (uint32_t i = 0; i < lods.lod[k].indexCount; ++i)
            ASSERT_LT(indices[lods.lod[k].firstIndex + i], vertices.size() - 5);
    }
    EXPECT_LE(lods.lod[lods.lodCount - 1].indexCount * 8, lods.lod[0].indexCount);
    // A box has nothing to simplify: one level.
    Mesh box = makeBox("b", glm::vec3(1.0f), 0);
    MeshGeometry bg;
    for (const Vertex& v : box.vertices)
        bg.vertices.push_back({v.position, v.normal, v.tangent, v.uv0});
    bg.indices = box.indices;
    EXPECT_EQ(appendMeshWithLods(bg, vertices, nullptr, indices).lodCount, 1u);
}

// Seed 004's LOD selection on the GPU: far trees and lamp posts drop to coarse levels.
TEST(World, LodsCutTrianglesAndKeepTheImage) {
    RenderOptions o = manyOptions(100000, 192, 108);
    RenderRun full = renderChecked(o);
    o.lod = true;
    RenderRun lod = renderChecked(o);
    uint64_t trisFull = view(full, "camera")["triangles_drawn"].get<uint64_t>();
    uint64_t trisLod = view(lod, "camera")["triangles_drawn"].get<uint64_t>();
    double p = psnr(lod.frames[0].rgba, full.frames[0].rgba);
    std::printf("[ figures ] many 100000 at 192x108: camera triangles %llu (LOD off) -> %llu "
                "(LOD on, %.1f%%), shadow %llu -> %llu, PSNR %.2f dB\n",
                (unsigned long long)trisFull, (unsigned long long)trisLod,
                100.0 * double(trisLod) / double(trisFull),
                (unsigned long long)view(full, "shadow")["triangles_drawn"].get<uint64_t>(),
                (unsigned long long)view(lod, "shadow")["triangles_drawn"].get<uint64_t>(), p);
    EXPECT_EQ(view(lod, "camera")["instances_drawn"], view(full, "camera")["instances_drawn"])
        << "LODs change what is drawn, not which instances";
    EXPECT_LE(double(trisLod), 0.30 * double(trisFull));
    EXPECT_GE(p, 35.0);
}

// Two-phase hierarchical-Z occlusion: the second frame draws what the first saw, builds the
// pyramid and culls most of what the frustum keeps, with an identical-looking image.
TEST(World, OcclusionCullsMostOfTheFrustumSetAndKeepsTheImage) {
    RenderOptions o = manyOptions(10000, 160, 90);
    RenderRun open = renderChecked(o);
    // Frame 1 has no history (phase 1 draws nothing, its empty pyramid hides nothing), frame 2
    // draws everything in phase 1 and learns what is hidden, frame 3 is the steady state.
    o.occlusion = true;
    o.frames = 3;
    RenderRun culled = renderChecked(o);
    const auto& cam = view(culled, "camera");
    uint32_t frustum = cam["frustum_visible"].get<uint32_t>();
    uint32_t hidden = cam["occlusion_culled"].get<uint32_t>();
    uint32_t drawn = cam["instances_drawn"].get<uint32_t>();
    double p = psnr(culled.frames[2].rgba, open.frames[0].rgba);
    std::printf("[ figures ] many 10000 at 160x90, frame 3: frustum keeps %u, occlusion culls %u "
                "(%.1f%%), drawn %u (%u in phase 1), PSNR %.2f dB\n",
                frustum, hidden, 100.0 * hidden / std::max(frustum, 1u), drawn,
                cam["drawn_in_phase1"].get<uint32_t>(), p);
    EXPECT_EQ(view(open, "camera")["frustum_visible"].get<uint32_t>(), frustum);
    EXPECT_EQ(drawn + hidden, frustum) << "every frustum-visible instance is drawn or hidden";
    EXPECT_GE(hidden * 2, frustum) << "at least half of what the frustum keeps is hidden";
    EXPECT_GE(p, 50.0);
    EXPECT_GT(cam["drawn_in_phase1"].get<uint32_t>(), 0u) << "last frame's set drawn first";
    std::vector<std::string> passes;
    for (auto& pass : culled.stats["passes"]) passes.push_back(pass["name"]);
    EXPECT_NE(std::find(passes.begin(), passes.end(), "hizBuild"), passes.end());
    EXPECT_NE(std::find(passes.begin(), passes.end(), "depthPrepassPhase2"), passes.end());
}

// Decoupled: every LOD indexes the baked vertices, so an object keeps one chart atlas and one
// sheet allocation whatever LOD the GPU picks; reconstruction finds every chunk it reads.
TEST(World, DecoupledLodsShareTheChartAtlas) {
    RenderOptions o = manyOptions(400, 160, 90);
    o.mode = RenderMode::Decoupled;
    o.frames = 2;
    RenderRun full = renderChecked(o);
    o.lod = true;
    RenderRun lod = renderChecked(o);
    double p = psnr(lod.frames[1].rgba, full.frames[1].rgba);
    std::printf("[ figures ] decoupled many 400 at 160x90: triangles %llu -> %llu with LODs, "
                "sheet blocks %llu / %llu, misses %llu, PSNR %.2f dB\n",
                (unsigned long long)full.stats["triangles_drawn"].get<uint64_t>(),
                (unsigned long long)lod.stats["triangles_drawn"].get<uint64_t>(),
                (unsigned long long)full.stats["sheet_blocks_allocated"].get<uint64_t>(),
                (unsigned long long)lod.stats["sheet_blocks_allocated"].get<uint64_t>(),
                (unsigned long long)lod.stats["reconstruction_misses"].get<uint64_t>(), p);
    EXPECT_LT(lod.stats["triangles_drawn"].get<uint64_t>(),
              full.stats["triangles_drawn"].get<uint64_t>());
    EXPECT_EQ(lod.stats["sheet_blocks_allocated"], full.stats["sheet_blocks_allocated"])
        << "the LOD does not change an object's allocation";
    EXPECT_EQ(lod.stats["reconstruction_misses"].get<uint64_t>(), 0u);
    EXPECT_GT(lod.stats["objects_decoupled"].get<uint64_t>(), 0u);
    EXPECT_GE(p, 35.0);
    // The visibility buffer rebuilds each pixel's triangle from the LOD the cull drew.
    o.marking = MarkingMode::Visibility;
    RenderRun vis = renderChecked(o);
    double pv = psnr(vis.frames[1].rgba, lod.frames[1].rgba);
    std::printf("[ figures ] decoupled many 400, LODs: visibility vs raster marking %.2f dB, "
                "misses %llu\n",
                pv, (unsigned long long)vis.stats["reconstruction_misses"].get<uint64_t>());
    EXPECT_EQ(vis.stats["reconstruction_misses"].get<uint64_t>(), 0u);
    EXPECT_GE(pv, 35.0);
}

// The decoupled frontend visits the grid's answer instead of every instance: it must be a
// superset of the instances whose margin-grown boxes meet the query, and much smaller than all.
TEST(World, InstanceGridQueriesAreSupersetsOfTheOverlaps) {
    Scene scene = makeBuiltinScene("many", {20000});
    std::vector<gpu::GpuInstance> instances;
    for (const Instance& inst : scene.instances) {
        Aabb b = transformAabb(scene.meshes[inst.mesh].bounds, inst.transform);
        gpu::GpuInstance g{};
        g.worldMin = b.min;
        g.worldMax = b.max;
        instances.push_back(g);
    }
    InstanceGrid grid;
    grid.build(instances);
    EXPECT_GT(grid.cellCount(), 100u);
    EXPECT_LE(grid.largeCount(), 2u) << "only the ground is larger than two cells";
    for (const Aabb& box : {Aabb{glm::vec3(-30, 0, -30), glm::vec3(40, 5, 90)},
                            Aabb{glm::vec3(200, -5, 100), glm::vec3(260, 50, 105)},
                            Aabb{glm::vec3(-1e4f), glm::vec3(-9e3f)}}) {
        std::vector<uint32_t> found;
        grid.query(box, found);
        std::set<uint32_t> set(found.begin(), found.end());
        EXPECT_EQ(set.size(), found.size()) << "each instance once";
        size_t overlapping = 0;
        for (uint32_t i = 0; i < instances.size(); ++i) {
            glm::vec3 margin = 0.1f * (instances[i].worldMax - instances[i].worldMin);
            Aabb grown{instances[i].worldMin - margin, instances[i].worldMax + margin};
            bool overlaps = glm::all(glm::lessThanEqual(grown.min, box.max)) &&
                            glm::all(glm::lessThanEqual(box.min, grown.max));
            overlapping += overlaps;
            if (overlaps) {
                EXPECT_TRUE(set.count(i)) << "instance " << i << " missed";
            }
        }
        EXPECT_LE(found.size(), 4 * overlapping + 200) << "the grid should narrow the search";
    }
}

// Decoupled with occlusion culling: the coarse allocation takes the GPU's visible set of last
// frame, so hidden instances hold no sheet space and the CPU visits only what was seen.
TEST(World, DecoupledAllocatesForTheGpuVisibleSet) {
    RenderOptions o = manyOptions(2000, 160, 90);
    o.mode = RenderMode::Decoupled;
    o.frames = 3;
    RenderRun open = renderChecked(o);
    o.occlusion = true;
    RenderRun culled = renderChecked(o);
    uint64_t objectsOpen = open.stats["objects_decoupled"].get<uint64_t>();
    uint64_t objectsCulled = culled.stats["objects_decoupled"].get<uint64_t>();
    uint32_t drawn = view(culled, "camera")["instances_drawn"].get<uint32_t>();
    double p = psnr(culled.frames[2].rgba, open.frames[2].rgba);
    std::printf("[ figures ] decoupled many 2000 at 160x90, frame 3: objects decoupled %llu "
                "(occlusion off) -> %llu (on, %u drawn), sheet blocks %llu -> %llu, PSNR %.2f dB\n",
                (unsigned long long)objectsOpen, (unsigned long long)objectsCulled, drawn,
                (unsigned long long)open.stats["sheet_blocks_allocated"].get<uint64_t>(),
                (unsigned long long)culled.stats["sheet_blocks_allocated"].get<uint64_t>(), p);
    EXPECT_LE(objectsCulled, drawn) << "only instances the GPU saw are allocated";
    EXPECT_LT(objectsCulled * 2, objectsOpen);
    EXPECT_GT(objectsCulled, 0u);
    EXPECT_EQ(culled.stats["reconstruction_misses"].get<uint64_t>(), 0u);
    EXPECT_GE(p, 35.0);
}

// bench --instance-scaling at test scale: two counts, two rounds, both modes. Each count's
// figure is the median of its per-round medians and each ratio is taken within a round, so the
// reported ratios must follow from the per-round figures; the counts must reach the scene.
TEST(World, BenchInstanceScalingReportsPerRoundMediansAndRatios) {
    BenchOptions b;
    b.scene = "builtin:many";
    b.width = 128, b.height = 72;
    b.frames = 2;
    b.rounds = 2;
    b.shadelsPerMetre = 4.0f; // unsplit: the GPU's instances are the scene's
    b.instanceScaling = {300, 40};
    b.cpuScopes = true;
    b.json = tempPath("instance_scaling.json");
    nlohmann::json out = runBench(sharedGpu(), b);
    EXPECT_EQ(takeJsonFile(b.json), out);
    EXPECT_EQ(out["lod"], "on");
    EXPECT_EQ(out["occlusion"], "on");
    for (const char* mode : {"forward", "decoupled"}) {
        const nlohmann::json& first = out["instance_scaling"][mode]["300"];
        for (uint32_t n : b.instanceScaling) {
            SCOPED_TRACE(std::string(mode) + " " + std::to_string(n));
            const nlohmann::json& row = out["instance_scaling"][mode][std::to_string(n)];
            ASSERT_TRUE(row.is_object()) << out["instance_scaling"].dump();
            EXPECT_EQ(row["instances"].get<uint32_t>(), n);
            EXPECT_GT(row["instances_drawn"].get<uint32_t>(), 0u);
            EXPECT_LE(row["instances_drawn"].get<uint32_t>(), n);
            const nlohmann::json& stats = out["modes"][std::string(mode) + "_" + std::to_string(n)];
            EXPECT_EQ(stats["culling"]["lod"], "on");
            EXPECT_EQ(stats["culling"]["occlusion"], "on");
            auto cpu = row["cpu_frame_ms_per_round"].get<std::vector<double>>();
            auto firstCpu = first["cpu_frame_ms_per_round"].get<std::vector<double>>();
            auto ratios = row["cpu_ratio_per_round"].get<std::vector<double>>();
            ASSERT_EQ(cpu.size(), b.rounds);
            ASSERT_EQ(ratios.size(), b.rounds);
            for (uint32_t i = 0; i < b.rounds; ++i) {
                EXPECT_GT(cpu[i], 0.0);
                EXPECT_DOUBLE_EQ(ratios[i], cpu[i] / firstCpu[i]);
            }
            EXPECT_DOUBLE_EQ(row["cpu_frame_ms"].get<double>(), median(cpu));
            EXPECT_DOUBLE_EQ(row["cpu_frame_ms_min"].get<double>(), std::min(cpu[0], cpu[1]));
            EXPECT_DOUBLE_EQ(row["cpu_frame_ms_max"].get<double>(), std::max(cpu[0], cpu[1]));
            EXPECT_DOUBLE_EQ(row["cpu_ratio"].get<double>(), median(ratios));
            EXPECT_GT(row["frame_ms"].get<double>(), 0.0);
            // The coarse allocation is the decoupled path's frontend step.
            EXPECT_EQ(row.contains("cpu_coarse_allocation_ms"), std::string(mode) == "decoupled");
        }
        EXPECT_DOUBLE_EQ(first["cpu_ratio"].get<double>(), 1.0);
        EXPECT_DOUBLE_EQ(
            out["ratios"][std::string("instance_scaling_cpu_") + mode + "_40"].get<double>(),
            out["instance_scaling"][mode]["40"]["cpu_ratio"].get<double>());
    }
}

TEST(World, BadInstanceScalingIsOneLineNamingTheInputAndExitCode2) {
    const std::pair<const char*, const char*> cases[] = {
        {"--scene builtin:many --instance-scaling ''", "--instance-scaling ''"},
        {"--scene builtin:many --instance-scaling 1000,0", "'0'"},
        {"--scene builtin:many --instance-scaling 10,1000001", "'1000001'"},
        {"--scene builtin:many --instance-scaling 10,ten", "'ten'"},
        {"--scene builtin:many --instance-scaling 10,10", "10 appears twice"},
        {"--scene builtin:default --instance-scaling 10,20", "builtin:default"},
        {"--scene builtin:many --instance-scaling 10 --mode sideways", "--mode sideways"},
        {"--scene builtin:many --instance-scaling 10 --occlusion 1", "--occlusion 1"},
        {"--scene builtin:many --instance-scaling 10 --instances 5", "--instances"},
        {"--scene builtin:many --mode forward", "--mode"}};
    for (const auto& [args, named] : cases) {
        std::string cmd = std::string("bench --size 16x16 --frames 1 ") + args, err;
        EXPECT_EQ(runShadel(cmd, err), 2) << cmd << ": " << err;
        EXPECT_EQ(err.rfind("shadel: ", 0), 0u) << cmd << ": " << err;
        EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << cmd << ": " << err;
        EXPECT_NE(err.find(named), std::string::npos) << cmd << ": " << err;
    }
}
