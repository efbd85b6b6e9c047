#version 460
// Indirect arguments of every material program's stages, from the chunk counts the work queue
// fill (and the near-change pass) appended to the program lists (program_types.h). Run after
// each of those passes, as shadel/dispatch_setup.comp is.
#include "shadel/shadel.glsl"
#include "common/dispatch_2d.h"
#include "materials/program_types.h"

layout(local_size_x = MATERIAL_MAX_PROGRAMS) in;
layout(push_constant, scalar) uniform Push {
    uint64_t header;
    uint programs;
} pc;

void main() {
    uint program = gl_LocalInvocationIndex;
    if (program >= pc.programs) return;
    Uvec4Buffer header = Uvec4Buffer(pc.header);
    uint chunks = header.v[program].w;
    header.v[program] = uvec4(dispatch2d(chunks), 1u, chunks);
}
