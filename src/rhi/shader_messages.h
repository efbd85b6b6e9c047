#pragma once
// The shader -> CPU message channel (seed 003's GPU inspection, asserts first): a buffer any
// shader appends to with atomics (shaders/common/bindless.glsl, SHADEL_ASSERT). After each
// frame the CPU decodes it, prints each distinct assert once with its source location, counts
// all of them, and resets it.
#include <cstdint>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "rhi/handles.h"

namespace shadel {

struct Gpu;

struct ShaderMessageChannel {
    BufferHandle buffer;
    std::set<std::tuple<uint32_t, uint32_t, uint32_t>> reported; // (assert, shader, line)
    uint64_t totalAsserts = 0;
    std::vector<std::string> lines; // every distinct message printed so far
};

void initShaderMessages(Gpu& gpu, ShaderMessageChannel& channel);
void destroyShaderMessages(Gpu& gpu, ShaderMessageChannel& channel);
uint64_t shaderMessagesAddress(const Gpu& gpu, const ShaderMessageChannel& channel);
// Call after the frame's GPU work completed. Returns the asserts raised by that frame.
uint32_t collectShaderMessages(Gpu& gpu, ShaderMessageChannel& channel);
const char* shaderName(uint32_t shaderId);

} // namespace shadel
