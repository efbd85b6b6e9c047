#version 460
// HDR scene colour -> display: exposure, the display curve, N x N supersample resolve (averaged after
// the tone curve, before sRGB encoding), sRGB encode, RGBA8 into a readback buffer. Alpha
// records coverage: 255 where any sample saw geometry (reversed-Z depth > 0). Workgroups of
// 32x8 (TONEMAP_GROUP_*): fewer of them than 8x8 cost lavapipe ~0.4 ms less at 1280x720.
#include "common/bindless.glsl"
#include "common/tone_curve.glsl"

layout(local_size_x = TONEMAP_GROUP_X, local_size_y = TONEMAP_GROUP_Y) in;

layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t pixels; // uint RGBA8 per pixel, row-major
    uint hdrSlot;
    uint depthSlot;
    uint width;
    uint height;
    uint ssaa;
} pc;

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= pc.width || p.y >= pc.height) return;
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    vec3 sum = vec3(0.0);
    bool covered = false;
    if (pc.ssaa == 1u) { // the common case, without the loops' bookkeeping (-1.3 ms at 1280x720)
        sum = toneCurve(max(fetchTextureUniform(pc.hdrSlot, ivec2(p), 0).rgb, vec3(0.0)) * f.exposure, f.tonemap);
        covered = fetchTextureUniform(pc.depthSlot, ivec2(p), 0).r > 0.0;
    } else {
        for (uint y = 0u; y < pc.ssaa; ++y) {
            for (uint x = 0u; x < pc.ssaa; ++x) {
                ivec2 q = ivec2(p * pc.ssaa + uvec2(x, y));
                vec3 hdr = fetchTextureUniform(pc.hdrSlot, q, 0).rgb;
                sum += toneCurve(max(hdr, vec3(0.0)) * f.exposure, f.tonemap);
                covered = covered || fetchTextureUniform(pc.depthSlot, q, 0).r > 0.0;
            }
        }
    }
    vec3 c = linearToSrgb(sum / float(pc.ssaa * pc.ssaa));
    UintBuffer(pc.pixels).v[p.y * pc.width + p.x] = packDisplayPixel(c, covered);
}
