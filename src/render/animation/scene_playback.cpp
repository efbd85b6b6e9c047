#include "render/animation/scene_playback.h"

#include <cstring>
#include <ctime>

#include "core/error.h"
#include "core/log.h"
#include "render/normal_matrix.h"
#include "scene/load.h"

namespace shadel {

ScenePlayback startPlayback(const std::string& spec, const SceneFileOptions& options,
                            double startTime, double step, Scene drawn) {
    ScenePlayback p;
    p.spec = spec;
    p.options = options;
    p.startTime = startTime;
    p.step = step;
    p.drawn = std::move(drawn);
    return p;
}

static double threadCpuMs() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

void prefetchPose(ScenePlayback& p, uint32_t frame) {
    SceneFileOptions options = p.options;
    options.time = p.startTime + double(frame) * p.step;
    p.nextFrame = frame;
    p.next = std::async(std::launch::async, [spec = p.spec, options] {
        // The first frame's import already gave the file's warnings; they would repeat.
        ScopedThreadLogLevel quiet(LogLevel::Error);
        ScenePlayback::Import out;
        out.start = std::chrono::steady_clock::now();
        double cpuStart = threadCpuMs();
        out.scene = loadScene(spec, options);
        out.cpuMs = threadCpuMs() - cpuStart;
        out.end = std::chrono::steady_clock::now();
        return out;
    });
}

static bool sameVertices(const Mesh& a, const Mesh& b) {
    return a.vertices.size() == b.vertices.size() &&
           std::memcmp(a.vertices.data(), b.vertices.data(), a.vertices.size() * sizeof(Vertex)) ==
               0;
}

void poseFrame(Gpu& gpu, ScenePlayback& p, uint32_t frame, GpuScene& gpuScene,
               std::vector<uint8_t>& reposed, bool gpuSkinned, std::vector<Aabb>* reposedFrom) {
    reposed.assign(gpuScene.instanceCount, 0);
    if (reposedFrom) reposedFrom->assign(gpuScene.instanceCount, Aabb{});
    SceneFileOptions options = p.options;
    options.time = p.startTime + double(frame) * p.step;
    Scene posed;
    p.lastWasPrefetched = false;
    if (p.next.valid() && p.nextFrame == frame) { // imported while the last frame rendered
        auto waitStart = std::chrono::steady_clock::now();
        p.lastImport = p.next.get(); // rethrows the worker's InputError
        p.prefetchWaitMs +=
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - waitStart)
                .count();
        p.prefetchCpuMs += p.lastImport.cpuMs;
        p.prefetched++;
        p.lastWasPrefetched = true;
        posed = std::move(p.lastImport.scene);
    } else {
        p.next = {}; // another frame's (waited for, not used)
        // The first frame's import already gave the file's warnings; they would repeat.
        ScopedThreadLogLevel quiet(LogLevel::Error);
        posed = loadScene(p.spec, options);
    }
    Scene& drawn = p.drawn;
    if (posed.meshes.size() != drawn.meshes.size() ||
        posed.instances.size() != drawn.instances.size() ||
        drawn.instances.size() != gpuScene.instanceCount)
        throw InputError(format("%s: at %.4f s the animated scene has %zu meshes / %zu "
                                "instances, not the %zu / %zu of the first frame",
                                p.spec.c_str(), *options.time, posed.meshes.size(),
                                posed.instances.size(), drawn.meshes.size(),
                                drawn.instances.size()));

    // Vertices of the meshes that deformed (morph targets, skins), through the upload's
    // vertex order (baked seams duplicate vertices; the fetch order permutes them).
    std::vector<uint8_t> meshMoved(drawn.meshes.size(), 0);
    for (size_t m = 0; m < drawn.meshes.size(); ++m) {
        Mesh& now = posed.meshes[m];
        if (now.vertices.size() != drawn.meshes[m].vertices.size() ||
            now.indices != drawn.meshes[m].indices)
            throw InputError(format("%s: mesh %zu (%s) changes topology over the animation",
                                    p.spec.c_str(), m, now.name.c_str()));
        if (sameVertices(now, drawn.meshes[m])) continue;
        meshMoved[m] = 1;
        p.meshesReposed++;
        if (!(gpuSkinned && now.skin)) { // else the skinning pass deforms it from the joints
            uint32_t first = uint32_t(gpuScene.meshInfo[m].vertexOffset);
            uint32_t end = m + 1 < gpuScene.meshInfo.size()
                               ? uint32_t(gpuScene.meshInfo[m + 1].vertexOffset)
                               : uint32_t(gpuScene.vertexSource.size());
            std::vector<gpu::GpuVertex> vertices(end - first);
            for (uint32_t v = first; v < end; ++v) {
                const Vertex& src = now.vertices[gpuScene.vertexSource[v]];
                vertices[v - first] = {src.position, src.normal, src.tangent, src.uv0, src.uv1};
            }
            uploadBuffer(gpu, gpuScene.vertices, vertices.data(),
                         vertices.size() * sizeof(gpu::GpuVertex),
                         VkDeviceSize(first) * sizeof(gpu::GpuVertex));
            p.verticesWritten += vertices.size();
        }
        gpu::GpuMesh& g = gpuScene.meshInfo[m];
        g.boundsMin = now.bounds.min;
        g.boundsMax = now.bounds.max;
        uploadBuffer(gpu, gpuScene.meshes, &g, sizeof(g), m * sizeof(gpu::GpuMesh));
        drawn.meshes[m] = std::move(now);
    }

    // Instances whose transform or mesh moved; the scene bounds (the sun's shadow fit) follow.
    gpuScene.bounds = Aabb{};
    bool anyReposed = false;
    for (size_t i = 0; i < drawn.instances.size(); ++i) {
        Instance& inst = drawn.instances[i];
        const Instance& now = posed.instances[i];
        if (now.mesh != inst.mesh)
            throw InputError(format("%s: instance %zu (%s) changes mesh over the animation",
                                    p.spec.c_str(), i, now.name.c_str()));
        bool moved = now.transform != inst.transform;
        if (moved || meshMoved[inst.mesh]) {
            inst.transform = now.transform;
            gpu::GpuInstance& g = gpuScene.instanceInfo[i];
            if (reposedFrom) (*reposedFrom)[i] = Aabb{g.worldMin, g.worldMax};
            g.model = inst.transform;
            g.normalMatrix = normalMatrixOf(inst.transform);
            Aabb world = transformAabb(drawn.meshes[inst.mesh].bounds, inst.transform);
            g.worldMin = world.min;
            g.worldMax = world.max;
            reposed[i] = 1;
            anyReposed = true;
            p.instancesReposed++;
        }
        gpuScene.bounds.extend(
            Aabb{gpuScene.instanceInfo[i].worldMin, gpuScene.instanceInfo[i].worldMax});
    }
    drawn.skinPoses = std::move(posed.skinPoses);
    if (anyReposed) // one copy: the GPU is idle between frames
        uploadBuffer(gpu, gpuScene.instances, gpuScene.instanceInfo.data(),
                     gpuScene.instanceInfo.size() * sizeof(gpu::GpuInstance));
}

} // namespace shadel
