#pragma once
// The shader -> CPU message channel (GPU inspection): a buffer any shader appends to
// with atomics: asserts (shaders/common/bindless.glsl, SHADEL_ASSERT) and prints of labelled
// values (shaders/common/shader_print.glsl, shaderPrintF...). After each frame the CPU decodes
// it, prints each distinct assert once with its source location, counts all of them, keeps the
// frame's prints in order, and resets it.
#include <cstdint>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "rhi/handles.h"

namespace shadel {

struct Gpu;

// One shader print record (shaderPrintRecord): a label (shaders/common/print_labels.h) and up to
// four values.
struct ShaderPrint {
    uint32_t label = 0;
    uint32_t shaderId = 0, line = 0;
    uint32_t type = 0, count = 0; // PRINT_UINT | PRINT_INT | PRINT_FLOAT, 1..4 values
    uint32_t tag = 0;             // the invocation that printed it (gPrintTag)
    uint32_t bits[4] = {};
    float f(int i) const;     // value i as a float (converted from ints)
    uint32_t u(int i) const;  // value i's bits as a uint
    std::string text() const; // "base colour 0.750 0.150 0.120  (shaders/...:40)"
};
const char* printLabelName(uint32_t label);

struct ShaderMessageChannel {
    BufferHandle buffer;
    std::set<std::tuple<uint32_t, uint32_t, uint32_t>> reported; // (assert, shader, line)
    uint64_t totalAsserts = 0;
    std::vector<std::string> lines;  // every distinct message printed so far
    std::vector<ShaderPrint> prints; // the last collected frame's, in the order they arrived
    uint32_t droppedMessages = 0;    // the last frame's records beyond the buffer's capacity
};

void initShaderMessages(Gpu& gpu, ShaderMessageChannel& channel);
void destroyShaderMessages(Gpu& gpu, ShaderMessageChannel& channel);
uint64_t shaderMessagesAddress(const Gpu& gpu, const ShaderMessageChannel& channel);
// Call after the frame's GPU work completed. Returns the asserts raised by that frame.
uint32_t collectShaderMessages(Gpu& gpu, ShaderMessageChannel& channel);
const char* shaderName(uint32_t shaderId);

} // namespace shadel
