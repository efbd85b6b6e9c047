#include "rhi/shader_messages.h"

#include <algorithm>
#include <cstring>

#include "common/asserts.h"
#include "common/print_labels.h"
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
    case ASSERT_SHADE_PIPELINE:
        return "a shading pipeline without a part this frame uses";
    case ASSERT_TEST:
        return "test assert";
    default:
        return "unknown assert";
    }
}
constexpr size_t kBufferSize =
    sizeof(ShaderMessagesHeader) + SHADER_MESSAGE_CAPACITY * sizeof(gpu::ShaderMessage);
} // namespace

const char* printLabelName(uint32_t label) {
    switch (label) {
    case PRINT_INSPECT_PIXEL:
        return "pixel";
    case PRINT_INSTANCE:
        return "instance";
    case PRINT_TRIANGLE:
        return "triangle";
    case PRINT_POSITION:
        return "position";
    case PRINT_GEOMETRIC_NORMAL:
        return "vertex normal";
    case PRINT_UV_LOD:
        return "uv footprint log2 (MIP)";
    case PRINT_BASE_COLOR:
        return "base colour";
    case PRINT_ROUGHNESS:
        return "roughness";
    case PRINT_METALLIC:
        return "metallic";
    case PRINT_SHADING_NORMAL:
        return "shading normal";
    case PRINT_OCCLUSION:
        return "occlusion";
    case PRINT_EMISSIVE:
        return "emissive";
    case PRINT_AMBIENT:
        return "ambient";
    case PRINT_SUN_SHADOW:
        return "sun shadow";
    case PRINT_SUN:
        return "sun";
    case PRINT_LIGHT:
        return "light (rgb, index)";
    case PRINT_SHADED:
        return "shaded (sum)";
    case PRINT_SHADEL_LOD:
        return "shadel lod, mip0, mip1, blend";
    case PRINT_SHADEL_CHUNK:
        return "chunk x, y, storage slot, mip";
    case PRINT_RECONSTRUCTED:
        return "reconstructed";
    case PRINT_OUTPUT:
        return "output";
    case PRINT_SHADING_BIAS:
        return "shading bias (frame), material rate bias, texture lod (1000: none)";
    case PRINT_FRAGMENT_DEPTH:
        return "fragment depth";
    case PRINT_TEST:
        return "test";
    default:
        return "(unknown label)";
    }
}

float ShaderPrint::f(int i) const {
    switch (type) {
    case PRINT_FLOAT: {
        float v;
        std::memcpy(&v, &bits[i], 4);
        return v;
    }
    case PRINT_INT:
        return float(int32_t(bits[i]));
    default:
        return float(bits[i]);
    }
}

uint32_t ShaderPrint::u(int i) const {
    return bits[i];
}

std::string ShaderPrint::text() const {
    std::string values;
    for (uint32_t i = 0; i < count; ++i) {
        if (type == PRINT_FLOAT)
            values += format(" %.4g", double(f(int(i))));
        else if (type == PRINT_INT)
            values += format(" %d", int32_t(bits[i]));
        else
            values += format(" %u", bits[i]);
    }
    return format("%-30s%s  (%s:%u)", printLabelName(label), values.c_str(), shaderName(shaderId),
                  line);
}

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
    channel.prints.clear();
    channel.droppedMessages = header.dropped;
    uint32_t asserts = 0;
    for (uint32_t i = 0; i < stored; ++i) {
        const gpu::ShaderMessage& m = entries[i];
        if (m.assertId & SHADER_PRINT_BIT) {
            ShaderPrint p;
            p.label = m.assertId & ~SHADER_PRINT_BIT;
            p.shaderId = m.shaderId;
            p.line = m.line;
            p.type = m.format & 0xFu;
            p.count = std::min((m.format >> 4) & 0xFu, 4u);
            p.tag = m.format >> 8;
            std::memcpy(p.bits, &m.values, sizeof(p.bits));
            channel.prints.push_back(p);
            continue;
        }
        ++asserts;
        auto key = std::make_tuple(m.assertId, m.shaderId, m.line);
        if (channel.reported.insert(key).second) {
            std::string line = format("shader assert: %s at %s:%u (values %u %u %u %u)",
                                      assertMessage(m.assertId), shaderName(m.shaderId), m.line,
                                      m.values.x, m.values.y, m.values.z, m.values.w);
            SHADEL_ERROR("%s", line.c_str());
            channel.lines.push_back(line);
        }
    }
    // Records past the capacity are not stored; count them as asserts only when no print could
    // have taken their place (a frame without prints).
    if (channel.prints.empty())
        asserts = header.count;
    else if (header.dropped)
        SHADEL_WARN("shader messages: %u records beyond the buffer's %u were dropped",
                    header.dropped, SHADER_MESSAGE_CAPACITY);
    channel.totalAsserts += asserts;
    std::memset(base, 0, kBufferSize);
    return asserts;
}

} // namespace shadel
