#version 460
// Compute marking (--marking visibility): one thread per screen pixel of the visibility buffer.
// Pixels of decoupled instances rebuild their shadel UV and its screen derivatives from the
// triangle and the pixel ray (shadel/vis_shadel.glsl) and mark what the resolve will read.
#include "shadel/marking.glsl"
#include "shadel/vis_shadel.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint visibilitySlot;
    uint width;
    uint height;
} pc;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(pc.width) || pixel.y >= int(pc.height)) return;
    uvec2 vis = loadVisibility(pc.visibilitySlot, pixel);
    if (vis.x == VISIBILITY_NONE) return;
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    GpuShadelObject o = ShadelObjectBuffer(s.objects).o[vis.x];
    if ((o.flags & SHADEL_OBJECT_DECOUPLED) == 0u) return; // forward (hybrid) instance
    GpuInstance inst = InstanceBuffer(f.instances).i[vis.x];
    VisShadel v = visShadelSample(f, s, inst, o, vis.y, pixel);
    markSample(s, o, v.shadelUv, v.texelDx, v.texelDy);
}
