#version 460
// Work queue setup: a prefix sum of every object's chunk count gives each object its segment
// of the queue and its own indirect dispatch arguments (seed: "Each object rendered has N
// blank ComputeIndirect calls"); also the indirect arguments of the fill and shading passes.
#include "shadel/shadel.glsl"

layout(local_size_x = 256) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

shared uint partial[256];

void main() {
    ShadelFrame s = ShadelFrameRef(FrameConstantsRef(pc.frame).f.shadel).s;
    UintBuffer chunks = UintBuffer(s.objectChunks);
    Uvec4Buffer dispatch = Uvec4Buffer(s.objectDispatch);
    uint lane = gl_LocalInvocationID.x;
    uint per = (s.objectCount + 255u) / 256u;
    uint begin = min(lane * per, s.objectCount), end = min(begin + per, s.objectCount);
    uint sum = 0u;
    for (uint i = begin; i < end; ++i) sum += chunks.v[i];
    partial[lane] = sum;
    barrier();
    if (lane == 0u) {
        uint running = 0u;
        for (uint i = 0u; i < 256u; ++i) {
            uint v = partial[i];
            partial[i] = running;
            running += v;
        }
        ShadelCountersRef counters = ShadelCountersRef(s.counters);
        uint total = running;
        counters.c.shadelsShaded = total * SHADEL_CHUNK * SHADEL_CHUNK;
        // 2-D dispatch: x stays under every device's maxComputeWorkGroupCount[0].
        uint x = min(total, 32768u);
        counters.c.shadeDispatch = uvec4(max(x, 1u), total == 0u ? 0u : (total + 32767u) / 32768u, 1u, total);
        uint blocks = counters.c.markedBlocks;
        counters.c.fillDispatch = uvec4((blocks + 63u) / 64u, 1u, 1u, blocks);
    }
    barrier();
    uint running = partial[lane];
    for (uint i = begin; i < end; ++i) {
        uint n = chunks.v[i];
        dispatch.v[i] = uvec4(n, 1u, 1u, running);
        running += n;
    }
}
