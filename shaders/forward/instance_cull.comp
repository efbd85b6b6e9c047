#version 460
// GPU-driven draw list: one thread per instance, frustum test against the view's planes,
// visible instances append an indexed-indirect command to the list of their material's
// bucket. firstInstance carries the instance id to the vertex shader.
#include "common/bindless.glsl"

layout(local_size_x = 64) in;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t draws;  // DrawIndexedCommand[DRAW_LIST_COUNT * maxDraws]
    uint64_t counts; // uint[DRAW_LIST_COUNT]
    uint maxDraws;
    uint shadowView; // 1: cull against the sun's shadow volume, only casters
} pc;

bool outside(vec4 plane, vec3 bmin, vec3 bmax) {
    vec3 p = vec3(plane.x >= 0.0 ? bmax.x : bmin.x, plane.y >= 0.0 ? bmax.y : bmin.y,
                  plane.z >= 0.0 ? bmax.z : bmin.z);
    return dot(plane.xyz, p) + plane.w < 0.0;
}

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    uint id = gl_GlobalInvocationID.x;
    if (id >= f.instanceCount) return;
    GpuInstance inst = InstanceBuffer(f.instances).i[id];
    for (int p = 0; p < 6; ++p) {
        vec4 plane = pc.shadowView != 0u ? f.shadowPlanes[p] : f.frustumPlanes[p];
        if (outside(plane, inst.worldMin, inst.worldMax)) return;
    }
    GpuMaterial mat = MaterialBuffer(f.materials).m[inst.material];
    uint list = (mat.flags & MATERIAL_ALPHA_BLEND) != 0u ? DRAW_LIST_BLEND : DRAW_LIST_OPAQUE;
    if (pc.shadowView != 0u && list == DRAW_LIST_BLEND) return;
    // Instances allocated in the shadel sheet this frame are drawn by the decoupled passes.
    if (pc.shadowView == 0u && f.shadel != 0ul &&
        (ShadelObjectBuffer(ShadelFrameRef(f.shadel).s.objects).o[id].flags & SHADEL_OBJECT_DECOUPLED) != 0u)
        list = list == DRAW_LIST_OPAQUE ? DRAW_LIST_DECOUPLED : DRAW_LIST_DECOUPLED_BLEND;
    GpuMesh mesh = MeshBuffer(f.meshes).m[inst.mesh];
    uint slot = atomicAdd(UintBuffer(pc.counts).v[list], 1u);
    SHADEL_ASSERT(f, slot < pc.maxDraws, ASSERT_DRAW_OVERFLOW, slot, pc.maxDraws);
    if (slot >= pc.maxDraws) return;
    DrawIndexedCommand cmd;
    cmd.indexCount = mesh.indexCount;
    cmd.instanceCount = 1u;
    cmd.firstIndex = mesh.firstIndex;
    cmd.vertexOffset = mesh.vertexOffset;
    cmd.firstInstance = id;
    DrawBuffer(pc.draws).d[list * pc.maxDraws + slot] = cmd;
}
