#version 460
// --visualize sheet: an image of the virtual sheet. Allocated rects are tinted by their MIP,
// blocks with any marked chunk are green, fully marked blocks blue (the seed's colours).
#include "shadel/shadel.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t pixels;
    uint width;
    uint height;
} pc;

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= pc.width || p.y >= pc.height) return;
    ShadelFrame s = ShadelFrameRef(FrameConstantsRef(pc.frame).f.shadel).s;
    uint side = min(pc.width, pc.height);
    vec3 c = vec3(0.02);
    if (p.x < side && p.y < side) {
        uvec2 b = p * s.sheetBlocks / side;
        uint block = b.y * s.sheetBlocks + b.x;
        uint owner = UintBuffer(s.allocId).v[block];
        if (owner != 0u) {
            float mip = float(owner & 15u);
            c = mix(vec3(0.25, 0.22, 0.3), vec3(0.45, 0.3, 0.2), mip / 9.0);
            uint64_t mask = Uint64Buffer(s.occupancy).v[block];
            if (mask == ~0ul) c = vec3(0.1, 0.25, 1.0);
            else if (mask != 0ul) c = vec3(0.1, 0.9, 0.2);
        }
    }
    uvec3 v = uvec3(clamp(c, 0.0, 1.0) * 255.0 + 0.5);
    UintBuffer(pc.pixels).v[p.y * pc.width + p.x] = v.r | (v.g << 8) | (v.b << 16) | (255u << 24);
}
