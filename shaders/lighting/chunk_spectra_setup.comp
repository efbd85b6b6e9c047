#version 460
// Feature spectra of the shadel path: each mode's chunk count (the classify phase's appends)
// becomes its 2-D indirect dispatch size, x kept under every device's maxComputeWorkGroupCount[0]
// as for the shading queue (shaders/shadel/dispatch_setup.comp); and the long-list pass's
// (chunk_long_lists.comp, an invocation per chunk, SPECTRA_LONG_LIST_GROUP a workgroup).
#include "common/bindless.glsl"
#include "common/dispatch_2d.h"

layout(local_size_x = SPECTRUM_MAX_MODES) in;
layout(buffer_reference, scalar) readonly buffer SetupSpectraFrameRef { SpectraFrame s; };
layout(push_constant, scalar) uniform Push { uint64_t spectraFrame; } pc;

void main() {
    SpectraFrame sf = SetupSpectraFrameRef(pc.spectraFrame).s;
    uint mode = gl_LocalInvocationIndex;
    if (mode == 0u && sf.chunkListCount != 0ul) {
        UintBuffer counts = UintBuffer(sf.chunkListCount);
        uint chunks = counts.v[2];
        uvec2 groups = dispatch2d((chunks + SPECTRA_LONG_LIST_GROUP - 1u) / SPECTRA_LONG_LIST_GROUP);
        counts.v[SPECTRA_LONG_LIST_DISPATCH] = groups.x;
        counts.v[SPECTRA_LONG_LIST_DISPATCH + 1u] = groups.y;
        counts.v[SPECTRA_LONG_LIST_DISPATCH + 2u] = 1u;
        counts.v[SPECTRA_LONG_LIST_DISPATCH + 3u] = chunks;
    }
    if (mode >= sf.modeCount) return;
    UintBuffer args = UintBuffer(sf.dispatch);
    uint n = args.v[mode * 4u + 3u];
    uvec2 groups = dispatch2d(n);
    args.v[mode * 4u] = groups.x;
    args.v[mode * 4u + 1u] = groups.y;
    args.v[mode * 4u + 2u] = 1u;
}
