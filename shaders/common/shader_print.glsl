// Shader prints (shaderPrintU, shaderPrintF and their vector forms: shaders send values to the
// CPU): a record of up to four values with a label (common/print_labels.h) goes through the shader
// message buffer the asserts use; the CPU decodes and prints it after the frame
// (rhi/shader_messages.h). Prints are meant for one pixel or shadel at a time: guard them with
// inspecting(f, pixel) (--inspect X,Y).
#ifndef SHADEL_SHADER_PRINT_GLSL
#define SHADEL_SHADER_PRINT_GLSL
#include "common/bindless.glsl"
#include "common/print_labels.h"

// Tags every record of this invocation (24 bits), so the CPU can tell apart the records of
// several invocations at one pixel (e.g. overdraw) even when they interleave.
uint gPrintTag = 0u;

void shaderPrintRecord(uint64_t messages, uint label, uint format, uvec4 bits, uint line) {
    if (messages == 0ul) return;
    ShaderMessages m = ShaderMessages(messages);
    uint slot = atomicAdd(m.count, 1u);
    if (slot < SHADER_MESSAGE_CAPACITY) {
        m.entries[slot].assertId = SHADER_PRINT_BIT | label;
        m.entries[slot].shaderId = SHADEL_SHADER_ID;
        m.entries[slot].line = line;
        m.entries[slot].format = format | (gPrintTag << 8);
        m.entries[slot].values = bits;
    } else {
        atomicAdd(m.dropped, 1u);
    }
}

// True only in pipelines built for --inspect (src/render/debug/inspect.h): otherwise every
// print is dead code and the driver drops it (compiled in but never taken, the prints made
// lavapipe's forward shading 2x slower).
layout(constant_id = 200) const bool kShaderPrintEnabled = false;

// The pixel --inspect picked (internal resolution); false for every pixel without it.
bool inspecting(FrameConstants f, uvec2 pixel) {
    return kShaderPrintEnabled && f.inspectPixel != INSPECT_OFF &&
           f.inspectPixel == (pixel.x | (pixel.y << 16));
}

#define SHADEL_PRINT_FMT(type, n) ((type) | ((n) << 4))
#define shaderPrintU(frame, label, v)                                                             \
    shaderPrintRecord((frame).messages, label, SHADEL_PRINT_FMT(PRINT_UINT, 1u),                   \
                      uvec4(uint(v), 0u, 0u, 0u), __LINE__)
#define shaderPrintU4(frame, label, v)                                                            \
    shaderPrintRecord((frame).messages, label, SHADEL_PRINT_FMT(PRINT_UINT, 4u), uvec4(v), __LINE__)
#define shaderPrintF(frame, label, v)                                                             \
    shaderPrintRecord((frame).messages, label, SHADEL_PRINT_FMT(PRINT_FLOAT, 1u),                  \
                      uvec4(floatBitsToUint(float(v)), 0u, 0u, 0u), __LINE__)
#define shaderPrintF2(frame, label, v)                                                            \
    shaderPrintRecord((frame).messages, label, SHADEL_PRINT_FMT(PRINT_FLOAT, 2u),                  \
                      uvec4(floatBitsToUint(vec2(v)), 0u, 0u), __LINE__)
#define shaderPrintF3(frame, label, v)                                                            \
    shaderPrintRecord((frame).messages, label, SHADEL_PRINT_FMT(PRINT_FLOAT, 3u),                  \
                      uvec4(floatBitsToUint(vec3(v)), 0u), __LINE__)
#define shaderPrintF4(frame, label, v)                                                            \
    shaderPrintRecord((frame).messages, label, SHADEL_PRINT_FMT(PRINT_FLOAT, 4u),                  \
                      floatBitsToUint(vec4(v)), __LINE__)
#endif
