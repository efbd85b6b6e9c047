// The global bindless table (rhi/bindless.h) and the buffer references every shader uses.
#ifndef SHADEL_BINDLESS_GLSL
#define SHADEL_BINDLESS_GLSL
#extension GL_EXT_nonuniform_qualifier : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference2 : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require

#include "common/shared_types.h"
#include "common/asserts.h"

layout(set = 0, binding = 0) uniform texture2D gTextures[];
layout(set = 0, binding = 0) uniform utexture2D gUTextures[]; // the same table, uint formats
// Storage images, one alias per format the engine writes.
layout(set = 0, binding = 1, rgba16f) uniform image2D gImagesRgba16f[];
layout(set = 0, binding = 1, rgba8) uniform image2D gImagesRgba8[];
layout(set = 0, binding = 1, r32ui) uniform uimage2D gImagesR32ui[];
layout(set = 0, binding = 1, rgba32ui) uniform uimage2D gImagesRgba32ui[];
layout(set = 0, binding = 2) uniform sampler gSamplers[SAMPLER_COUNT];
layout(set = 0, binding = 2) uniform samplerShadow gShadowSamplers[SAMPLER_COUNT];

// The engine's samplers; material textures use their slot's (materialSampler, material.glsl).
#define SAMPLER_LINEAR_REPEAT 0
#define SAMPLER_LINEAR_CLAMP 1
#define SAMPLER_NEAREST_CLAMP 2
#define SAMPLER_SHADOW 3

layout(buffer_reference, scalar) readonly buffer FrameConstantsRef { FrameConstants f; };
layout(buffer_reference, scalar) readonly buffer VertexBuffer { GpuVertex v[]; };
layout(buffer_reference, scalar) readonly buffer IndexBuffer { uint i[]; };
layout(buffer_reference, scalar) readonly buffer MeshBuffer { GpuMesh m[]; };
layout(buffer_reference, scalar) readonly buffer InstanceBuffer { GpuInstance i[]; };
layout(buffer_reference, scalar) readonly buffer MaterialBuffer { GpuMaterial m[]; };
layout(buffer_reference, scalar) readonly buffer LightBuffer { GpuLight l[]; };
layout(buffer_reference, scalar) buffer UintBuffer { uint v[]; };
layout(buffer_reference, scalar) buffer Uint64Buffer { uint64_t v[]; };
layout(buffer_reference, scalar) readonly buffer Vec2Buffer { vec2 v[]; };
layout(buffer_reference, scalar) readonly buffer ShadelFrameRef { ShadelFrame s; };
layout(buffer_reference, scalar) readonly buffer ShadelObjectBuffer { GpuShadelObject o[]; };
// One object read in place: its fields are loaded where they are used. Copying the struct into
// a local (`GpuShadelObject o = ...o[i]`) loaded all of it, per-MIP arrays included (indexed at
// run time, so nothing was dead), in every pixel of marking and reconstruction.
layout(buffer_reference, scalar) readonly buffer ShadelObjectRef { GpuShadelObject v; };
layout(buffer_reference, scalar) buffer DrawBuffer { DrawIndexedCommand d[]; };
layout(buffer_reference, scalar) buffer ShaderMessages {
    uint count;
    uint dropped;
    uint pad0;
    uint pad1;
    ShaderMessage entries[];
};

vec4 sampleTexture(uint slot, uint samplerId, vec2 uv, vec2 dx, vec2 dy) {
    return textureGrad(sampler2D(gTextures[nonuniformEXT(slot)], gSamplers[nonuniformEXT(samplerId)]),
                       uv, dx, dy);
}
vec4 sampleTextureLod(uint slot, uint samplerId, vec2 uv, float lod) {
    return textureLod(sampler2D(gTextures[nonuniformEXT(slot)], gSamplers[nonuniformEXT(samplerId)]),
                      uv, lod);
}
vec4 fetchTexture(uint slot, ivec2 texel, int lod) {
    return texelFetch(gTextures[nonuniformEXT(slot)], texel, lod);
}
// For slots that are the same for every invocation of a draw or dispatch (push or frame
// constants): no non-uniform indexing, so drivers take their fast descriptor path.
vec4 fetchTextureUniform(uint slot, ivec2 texel, int lod) {
    return texelFetch(gTextures[slot], texel, lod);
}

#ifndef SHADEL_SHADER_ID
#define SHADEL_SHADER_ID 0
#endif

// Appends an assert record; the CPU prints each (id, shader, line) once and counts them.
void shaderAssertFailed(uint64_t messages, uint id, uint line, uvec4 values) {
    if (messages == 0ul) return;
    ShaderMessages m = ShaderMessages(messages);
    uint slot = atomicAdd(m.count, 1u);
    if (slot < SHADER_MESSAGE_CAPACITY) {
        m.entries[slot].assertId = id;
        m.entries[slot].shaderId = SHADEL_SHADER_ID;
        m.entries[slot].line = line;
        m.entries[slot].values = values;
    } else {
        atomicAdd(m.dropped, 1u);
    }
}
#define SHADEL_ASSERT(frame, cond, id, v0, v1)                                                    \
    if (!(cond)) shaderAssertFailed((frame).messages, id, __LINE__, uvec4(uint(v0), uint(v1), 0u, 0u))
#endif
