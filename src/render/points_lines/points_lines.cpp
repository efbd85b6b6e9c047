#include "render/points_lines/points_lines.h"

#include "core/error.h"
#include "core/log.h"
#include "render/renderer.h"
#include "rhi/gpu.h"
#include "rhi/pipeline.h"
#include "rhi/rendering.h"

namespace shadel {

namespace {
// shaders/points_lines/points_lines.vert's PointLineVertex.
struct PointLineVertex {
    glm::vec3 position; // world
    glm::vec4 color;    // linear, unlit radiance
};
struct PointsLinesPush {
    uint64_t frame;
    uint64_t vertices;
};
} // namespace

struct PointsLinesState {
    BufferHandle vertices; // points first, then line pairs
    uint32_t pointCount = 0, lineVertexCount = 0;
    Pipeline points, lines;
};

void PointsLinesStateDeleter::operator()(PointsLinesState* s) const {
    delete s;
}

PointsLinesStatePtr createPointsLines(Renderer& r, const Scene& scene) {
    std::vector<PointLineVertex> points, lines;
    for (const PointLineSet& set : scene.pointLines) {
        glm::vec4 factor = set.material < scene.materials.size()
                               ? scene.materials[set.material].baseColorFactor
                               : glm::vec4(1.0f);
        auto& out = set.lines ? lines : points;
        for (size_t v = 0; v < set.vertices.size(); ++v) {
            glm::vec4 c = v < set.colors.size() ? set.colors[v] : glm::vec4(1.0f);
            out.push_back(
                {glm::vec3(set.transform * glm::vec4(set.vertices[v].position, 1.0f)), factor * c});
        }
    }
    if (points.empty() && lines.empty()) return nullptr;
    Gpu& gpu = *r.gpu;
    PointsLinesStatePtr s(new PointsLinesState);
    s->pointCount = uint32_t(points.size());
    s->lineVertexCount = uint32_t(lines.size());
    points.insert(points.end(), lines.begin(), lines.end());
    VkDeviceSize bytes = points.size() * sizeof(PointLineVertex);
    s->vertices = createBuffer(gpu, {"pointsLines.vertices", bytes, 0, MemoryKind::DeviceLocal});
    if (!s->vertices) throw DeviceError("out of GPU memory for points and lines");
    uploadBuffer(gpu, s->vertices, points.data(), bytes);
    GraphicsPipelineDesc desc;
    desc.vertexShader = "points_lines_points_lines.vert.spv";
    desc.fragmentShader = "points_lines_points_lines.frag.spv";
    desc.colorFormats = {VK_FORMAT_R16G16B16A16_SFLOAT};
    desc.depthFormat = VK_FORMAT_D32_SFLOAT;
    desc.cullMode = VK_CULL_MODE_NONE;
    desc.name = "pointsLines.points";
    desc.topology = VK_PRIMITIVE_TOPOLOGY_POINT_LIST;
    s->points = createGraphicsPipeline(gpu, desc);
    desc.name = "pointsLines.lines";
    desc.topology = VK_PRIMITIVE_TOPOLOGY_LINE_LIST;
    s->lines = createGraphicsPipeline(gpu, desc);
    return s;
}

void destroyPointsLines(Renderer& r, PointsLinesState& s) {
    Gpu& gpu = *r.gpu;
    if (s.vertices) destroy(gpu, s.vertices);
    destroy(gpu, s.points);
    destroy(gpu, s.lines);
}

uint32_t pointsLinesVertexCount(const PointsLinesState& s) {
    return s.pointCount + s.lineVertexCount;
}

void recordPointsLines(Renderer& r, FrameRecorder& rec, uint64_t frame) {
    if (!r.pointsLines) return;
    pass(rec, "pointsLines", [&, frame](VkCommandBuffer cmd) {
        Gpu& gpu = *r.gpu;
        PointsLinesState& s = *r.pointsLines;
        // After every pass that wrote colour or depth (raster or compute).
        memoryBarrier(cmd,
                      VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT |
                          VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT |
                          VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
                          VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
                          VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT |
                          VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                          VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                      VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT |
                          VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
                          VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                          VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
        beginRendering(cmd, r.internalWidth, r.internalHeight, {{vkView(gpu, r.hdrTarget)}},
                       {vkView(gpu, r.depthTarget)});
        PointsLinesPush push{frame, address(gpu, s.vertices)};
        if (s.pointCount) {
            bind(gpu, cmd, s.points);
            pushConstants(gpu, cmd, push);
            vkCmdDraw(cmd, s.pointCount, 1, 0, 0);
        }
        if (s.lineVertexCount) {
            bind(gpu, cmd, s.lines);
            pushConstants(gpu, cmd, push);
            vkCmdDraw(cmd, s.lineVertexCount, 1, s.pointCount, 0);
        }
        vkCmdEndRendering(cmd);
    });
}

} // namespace shadel
