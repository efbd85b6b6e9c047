#include "render/skinning/skinning.h"

#include <cstring>

#include "core/error.h"
#include "core/log.h"
#include "render/gpu_scene.h"
#include "render/renderer.h"
#include "rhi/gpu.h"
#include "rhi/pipeline.h"

namespace shadel {

namespace {
// shaders/skinning/skin.comp's SkinVertex.
struct SkinVertex {
    uint32_t target;   // index into the deformed vertex buffer
    glm::uvec4 joints; // into the joint matrices of every skin, laid end to end
    glm::vec4 weights;
};
static_assert(sizeof(SkinVertex) == 36);

struct SkinPush {
    uint64_t bindVertices; // GpuVertex[] (unskinned, one per SkinVertex)
    uint64_t skinVertices; // SkinVertex[]
    uint64_t matrices;     // mat4[]
    uint64_t deformed;     // GpuVertex[] (the whole unified buffer)
    uint32_t count;
};
} // namespace

struct SkinningState {
    BufferHandle deformed, bindVertices, skinVertices, matrices;
    std::vector<uint32_t> firstMatrix; // per skin pose
    uint32_t matrixCount = 0;
    uint32_t vertexCount = 0;
    std::vector<uint32_t> meshes; // skinned by this pass
    uint64_t poseVersion = 0;
    Pipeline pipeline;
};

void SkinningStateDeleter::operator()(SkinningState* s) const {
    delete s;
}

SkinningStatePtr createSkinning(Renderer& r, const Scene& scene, const GpuScene& gpuScene) {
    Gpu& gpu = *r.gpu;
    std::vector<uint32_t> firstMatrix;
    uint32_t matrixCount = 0;
    for (const SkinPose& p : scene.skinPoses) {
        firstMatrix.push_back(matrixCount);
        matrixCount += uint32_t(p.joints.size());
    }
    // Every vertex of the unified buffer whose mesh carries GPU skinning input, through the
    // upload's order (baked seams duplicate vertices, fetch order permutes them).
    std::vector<gpu::GpuVertex> bind;
    std::vector<SkinVertex> skin;
    std::vector<uint32_t> meshes;
    for (size_t m = 0; m < scene.meshes.size() && m < gpuScene.meshInfo.size(); ++m) {
        const MeshSkin* s = scene.meshes[m].skin.get();
        if (!s || s->bindVertices.size() != scene.meshes[m].vertices.size() ||
            s->skin >= scene.skinPoses.size())
            continue;
        meshes.push_back(uint32_t(m));
        uint32_t first = uint32_t(gpuScene.meshInfo[m].vertexOffset);
        uint32_t end = m + 1 < gpuScene.meshInfo.size()
                           ? uint32_t(gpuScene.meshInfo[m + 1].vertexOffset)
                           : uint32_t(gpuScene.vertexSource.size());
        for (uint32_t v = first; v < end; ++v) {
            uint32_t src = gpuScene.vertexSource[v];
            const Vertex& b = s->bindVertices[src];
            bind.push_back({b.position, b.normal, b.tangent, b.uv0, b.uv1});
            skin.push_back({v, s->joints[src] + glm::uvec4(firstMatrix[s->skin]), s->weights[src]});
        }
    }
    if (skin.empty()) return nullptr;
    SkinningStatePtr st(new SkinningState);
    st->firstMatrix = firstMatrix;
    st->meshes = std::move(meshes);
    st->matrixCount = matrixCount;
    st->vertexCount = uint32_t(skin.size());
    VkDeviceSize total = size(gpu, gpuScene.vertices);
    auto device = [&](const char* name, VkDeviceSize bytes) {
        BufferHandle b = createBuffer(gpu, {name, bytes, 0, MemoryKind::DeviceLocal});
        if (!b) throw DeviceError(format("out of GPU memory for %s", name));
        return b;
    };
    // Also the skinned meshes' BLAS input (render/raytracing) where the device traces rays.
    VkBufferUsageFlags rtInput =
        gpu.device.optional.rayQuery
            ? VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR
            : 0;
    st->deformed =
        createBuffer(gpu, {"skinning.deformedVertices", total, rtInput, MemoryKind::DeviceLocal});
    if (!st->deformed) throw DeviceError("out of GPU memory for skinning.deformedVertices");
    st->bindVertices = device("skinning.bindVertices", bind.size() * sizeof(gpu::GpuVertex));
    st->skinVertices = device("skinning.influences", skin.size() * sizeof(SkinVertex));
    st->matrices = createBuffer(gpu, {"skinning.jointMatrices",
                                      std::max<VkDeviceSize>(matrixCount, 1) * sizeof(glm::mat4), 0,
                                      MemoryKind::Upload});
    if (!st->matrices) throw DeviceError("out of host-visible memory for joint matrices");
    uploadBuffer(gpu, st->bindVertices, bind.data(), bind.size() * sizeof(gpu::GpuVertex));
    uploadBuffer(gpu, st->skinVertices, skin.data(), skin.size() * sizeof(SkinVertex));
    // Unskinned meshes are the unified buffer's vertices, copied once.
    immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
        VkBufferCopy copy{0, 0, total};
        vkCmdCopyBuffer(cmd, vkBuffer(gpu, gpuScene.vertices), vkBuffer(gpu, st->deformed), 1,
                        &copy);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                      VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
    });
    st->pipeline = createComputePipeline(gpu, "skinning", "skinning_skin.comp.spv");
    setSkinPoses(r, *st, scene.skinPoses);
    return st;
}

void destroySkinning(Renderer& r, SkinningState& s) {
    Gpu& gpu = *r.gpu;
    for (BufferHandle b : {s.deformed, s.bindVertices, s.skinVertices, s.matrices})
        if (b) destroy(gpu, b);
    destroy(gpu, s.pipeline);
}

void setSkinPoses(Renderer& r, SkinningState& s, const std::vector<SkinPose>& poses) {
    if (poses.size() != s.firstMatrix.size())
        throw InputError(
            format("skinning: %zu skin poses, expected %zu", poses.size(), s.firstMatrix.size()));
    auto* out = static_cast<glm::mat4*>(mapped(*r.gpu, s.matrices));
    bool changed = s.poseVersion == 0;
    for (size_t k = 0; k < poses.size(); ++k) {
        uint32_t count = k + 1 < s.firstMatrix.size() ? s.firstMatrix[k + 1] - s.firstMatrix[k]
                                                      : s.matrixCount - s.firstMatrix[k];
        if (poses[k].joints.size() != count)
            throw InputError(format("skinning: skin %zu has %zu joints, expected %u", k,
                                    poses[k].joints.size(), count));
        changed = changed || std::memcmp(out + s.firstMatrix[k], poses[k].joints.data(),
                                         count * sizeof(glm::mat4)) != 0;
        std::memcpy(out + s.firstMatrix[k], poses[k].joints.data(), count * sizeof(glm::mat4));
    }
    if (changed) s.poseVersion++;
}

uint64_t skinnedVerticesAddress(const Renderer& r, const SkinningState& s) {
    return address(*r.gpu, s.deformed);
}

uint32_t skinnedVertexCount(const SkinningState& s) {
    return s.vertexCount;
}

const std::vector<uint32_t>& skinnedMeshes(const SkinningState& s) {
    return s.meshes;
}

uint64_t skinPoseVersion(const SkinningState& s) {
    return s.poseVersion;
}

void recordSkinning(Renderer& r, VkCommandBuffer cmd) {
    Gpu& gpu = *r.gpu;
    SkinningState& s = *r.skinning;
    // Last frame's draws read the deformed buffer: they finish before it is rewritten.
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    bind(gpu, cmd, s.pipeline);
    SkinPush push{address(gpu, s.bindVertices), address(gpu, s.skinVertices),
                  address(gpu, s.matrices), address(gpu, s.deformed), s.vertexCount};
    pushConstants(gpu, cmd, push);
    vkCmdDispatch(cmd, (s.vertexCount + 63) / 64, 1, 1);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
}

} // namespace shadel
