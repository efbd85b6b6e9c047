#version 460
// HDR scene colour -> display: exposure, the display curve, N x N supersample resolve (averaged after
// the tone curve, before sRGB encoding), sRGB encode, RGBA8 into a readback buffer. Alpha
// records coverage: the fraction of samples that saw geometry (reversed-Z depth > 0). Workgroups of
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
    if (pc.ssaa == 1u) { // the common case, without the loops' bookkeeping (-1.3 ms at 1280x720)
        vec3 hdr = max(fetchTextureUniform(pc.hdrSlot, ivec2(p), 0).rgb, vec3(0.0));
        bool covered = fetchTextureUniform(pc.depthSlot, ivec2(p), 0).r > 0.0;
        vec3 c = linearToSrgb(toneCurve(hdr * f.exposure, f.tonemap));
        UintBuffer(pc.pixels).v[p.y * pc.width + p.x] = packDisplayPixel(c, covered);
        return;
    }
    // Supersampled: alpha is the fraction of covered samples. Over a solid background the colour
    // is the covered samples' own (straight alpha, as PNG stores it: composited over that
    // background it gives the supersampled picture); over the environment it is every sample's.
    vec3 sumAll = vec3(0.0), sumCovered = vec3(0.0);
    uint coveredSamples = 0u;
    for (uint y = 0u; y < pc.ssaa; ++y) {
        for (uint x = 0u; x < pc.ssaa; ++x) {
            ivec2 q = ivec2(p * pc.ssaa + uvec2(x, y));
            vec3 c = toneCurve(max(fetchTextureUniform(pc.hdrSlot, q, 0).rgb, vec3(0.0)) * f.exposure, f.tonemap);
            sumAll += c;
            if (fetchTextureUniform(pc.depthSlot, q, 0).r > 0.0) {
                sumCovered += c;
                ++coveredSamples;
            }
        }
    }
    float samples = float(pc.ssaa * pc.ssaa);
    bool straight = f.backgroundEnvironment == 0u && coveredSamples > 0u;
    vec3 c = straight ? sumCovered / float(coveredSamples) : sumAll / samples;
    UintBuffer(pc.pixels).v[p.y * pc.width + p.x] =
        packDisplayPixel(linearToSrgb(c), float(coveredSamples) / samples);
}
