#version 460
// The resolve's rebuild pass (see resolve.comp): one invocation per pixel the resolve listed
// (misses, overflow, camera-cut samples: rare), rebuilt from the visibility buffer and shaded
// as the inline rebuild would (shadel/resolve_pixel.glsl resolveRebuilt). Indirect dispatch
// (resolve_rebuild_args.comp), 2-D past 65535 groups (common/dispatch_2d.h).
#include "shadel/resolve_pixel.glsl"
#include "common/dispatch_2d.h"

layout(local_size_x = 64) in;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    ResolveRebuildList list = ResolveRebuildList(pc.rebuildList);
    uint index = dispatch2dGroup() * 64u + gl_LocalInvocationIndex;
    uvec4 counts = uvec4(0u);
    if (index < list.count) {
        uint packed = list.pixels[index];
        ivec2 pixel = ivec2(packed & 0xFFFFu, packed >> 16);
        ivec2 origin = pixel & ~1;
        int i = (pixel.x & 1) | ((pixel.y & 1) << 1);
        uvec2 current = uvec2(VISIBILITY_NONE);
        VisQuad q;
        ShadelObjectRef o;
        GpuInstance inst;
        vec4 color = resolveRebuilt(f, s, origin, i, pixel, current, o, inst, q, counts);
        writeResolvedPixel(f, pixel, color);
    }
    countResolvedPixels(s, counts);
}
