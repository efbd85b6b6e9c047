#include "rhi/shader_messages.h"

#include <cstring>

#include "common/asserts.h"
#include "common/shared_types.h"
#include "core/log.h"
#include "rhi/gpu.h"

namespace shadel {

namespace {
struct ShaderMessagesHeader {
    uint32_t count;
    uint32_t dropped;
    uint32_t pad0, pad1;
};
struct ShaderTableEntry {
    uint32_t id;
    const char* name;
};
const ShaderTableEntry kShaders[] = {
#include "shader_table.inc"
};

const char* assertMessage(uint32_t id) {
    switch (id) {
    case ASSERT_INSTANCE_RANGE:
        return "instance index out of range";
    case ASSERT_MATERIAL_RANGE:
        return "material index out of range";
    case ASSERT_DRAW_OVERFLOW:
        return "more draws than the indirect buffer holds";
    case ASSERT_NON_FINITE:
        return "non-finite shading result";
    case ASSERT_SHADEL_SLOT:
        return "shadel storage slot out of range";
    case ASSERT_TRIANGLE_ID:
        return "triangle id out of range";
    case ASSERT_TEST:
        return "test assert";
    default:
        return "unknown assert";
    }
}
constexpr size_t kBufferSize =
    sizeof(ShaderMessagesHeader) + SHADER_MESSAGE_CAPACITY * sizeof(gpu::ShaderMessage);
} // namespace

const char* shaderName(uint32_t shaderId) {
    for (const ShaderTableEntry& e : kShaders)
        if (e.id == shaderId) return e.name;
    return "(unknown shader)";
}

void initShaderMessages(Gpu& gpu, ShaderMessageChannel& channel) {
    channel.buffer = createBuffer(gpu, {"shaderMessages", kBufferSize, 0, MemoryKind::Readback});
    if (!channel.buffer) throw DeviceError("cannot allocate the shader message buffer");
    std::memset(mapped(gpu, channel.buffer), 0, kBufferSize);
}

void destroyShaderMessages(Gpu& gpu, ShaderMessageChannel& channel) {
    destroy(gpu, channel.buffer);
    channel.buffer = {};
}

uint64_t shaderMessagesAddress(const Gpu& gpu, const ShaderMessageChannel& channel) {
    return address(gpu, channel.buffer);
}

uint32_t collectShaderMessages(Gpu& gpu, ShaderMessageChannel& channel) {
    auto* base = static_cast<uint8_t*>(mapped(gpu, channel.buffer));
    ShaderMessagesHeader header;
    std::memcpy(&header, base, sizeof(header));
    uint32_t stored = std::min(header.count, SHADER_MESSAGE_CAPACITY);
    auto* entries = reinterpret_cast<const gpu::ShaderMessage*>(base + sizeof(header));
    for (uint32_t i = 0; i < stored; ++i) {
        const gpu::ShaderMessage& m = entries[i];
        auto key = std::make_tuple(m.assertId, m.shaderId, m.line);
        if (channel.reported.insert(key).second) {
            std::string line = format("shader assert: %s at %s:%u (values %u %u %u %u)",
                                      assertMessage(m.assertId), shaderName(m.shaderId), m.line,
                                      m.values.x, m.values.y, m.values.z, m.values.w);
            SHADEL_ERROR("%s", line.c_str());
            channel.lines.push_back(line);
        }
    }
    channel.totalAsserts += header.count;
    std::memset(base, 0, kBufferSize);
    return header.count;
}

} // namespace shadel
