// Material programs (render/materials): what the work queue fill and the program stages share.
// Shared by C++ and GLSL (scalar layout).
#ifndef SHADEL_MATERIALS_PROGRAM_TYPES_H
#define SHADEL_MATERIALS_PROGRAM_TYPES_H

// A decoupled object's program is in bits 24..31 of its GpuShadelObject flags: 0 is the built-in
// glTF PBR program (the shading classes of shaders/shadel/shade.comp), k > 0 the (k - 1)-th of
// the renderer's loaded programs, whose chunks go to that program's list instead.
#define SHADEL_OBJECT_PROGRAM_SHIFT 24u
#define MATERIAL_MAX_PROGRAMS 32u
// The object's program runs every frame ("rate": "every_frame"): its chunks are never carried
// over, so a stage that accumulates through prevSample sees every frame.
#define SHADEL_OBJECT_PROGRAM_EVERY_FRAME (1u << 23u)

// The program lists (render/materials/material_programs.h): a header, per program a uvec4 of
// indirect dispatch arguments (x, y, z) and its chunk count (w), and per program a list of
// capacityChunks entries (indices into the shading queue). The work queue fill and the
// near-change pass take their addresses in push constants (0: no program is loaded).
#define MATERIAL_LIST_HEADER_BYTES (16u * MATERIAL_MAX_PROGRAMS)

#ifndef __cplusplus
// Appends queued chunk `queued` of an object to its program's list; false (nothing appended)
// for the built-in program's objects or when no program is loaded.
bool appendToProgramList(uint64_t header, uint64_t queues, uint capacity, uint objectFlags,
                         uint queued) {
    uint program = objectFlags >> SHADEL_OBJECT_PROGRAM_SHIFT;
    if (program == 0u || header == 0ul) return false;
    uint place = atomicAdd(Uvec4Buffer(header).v[program - 1u].w, 1u);
    UintBuffer(queues).v[(program - 1u) * capacity + place] = queued;
    return true;
}
#endif

#endif
