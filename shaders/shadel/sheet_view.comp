#version 460
// --visualize sheet: an image of the virtual sheet. The full width (every MIP region, one
// column each, finest at the left) and the rows in use, stretched to the image. Allocated
// rects are tinted by their MIP, blocks with any marked chunk are green, fully marked blocks
// blue, region borders grey.
#include "shadel/shadel.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t pixels;
    uint width;
    uint height;
    uint rowsInUse; // sheet rows (blocks) that hold any rect this frame
} pc;

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= pc.width || p.y >= pc.height) return;
    ShadelFrame s = ShadelFrameRef(FrameConstantsRef(pc.frame).f.shadel).s;
    uvec2 b = uvec2(p.x * s.sheetBlocks / pc.width, p.y * max(pc.rowsInUse, 1u) / pc.height);
    uint block = b.y * s.sheetBlocks + b.x;
    uint owner = UintBuffer(s.allocId).v[block];
    vec3 c = vec3(0.02);
    if (owner != 0u) {
        float mip = float(owner & 15u);
        c = mix(vec3(0.35, 0.3, 0.45), vec3(0.5, 0.35, 0.2), mip / 9.0);
        uint64_t mask = Uint64Buffer(s.occupancy).v[block];
        if (mask == ~0ul) c = vec3(0.1, 0.25, 1.0);
        else if (mask != 0ul) c = vec3(0.1, 0.9, 0.2);
    }
    // Region borders: where the block column changes MIP region.
    uint nextX = min((p.x + 1u) * s.sheetBlocks / pc.width, s.sheetBlocks - 1u);
    for (uint k = 1u; k < SHADEL_MAX_MIPS; ++k)
        if (b.x < s.regionStart[k] && nextX >= s.regionStart[k]) c = vec3(0.5);
    uvec3 v = uvec3(clamp(c, 0.0, 1.0) * 255.0 + 0.5);
    // Keep the alpha (coverage of the scene image) so the frame's statistics stay meaningful.
    uint index = p.y * pc.width + p.x;
    uint coverage = UintBuffer(pc.pixels).v[index] & 0xFF000000u;
    UintBuffer(pc.pixels).v[index] = v.r | (v.g << 8) | (v.b << 16) | coverage;
}
