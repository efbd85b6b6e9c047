#version 460
// The temporal resolve: this frame's jittered scene colour accumulated into the history of
// earlier frames. Per output pixel (the unjittered pixel centre):
//   1. this frame's colour there, reconstructed from the 3x3 jittered samples around it with a
//      Gaussian fit of a Blackman-Harris window (the samples sit at their jittered positions);
//   2. the motion of the closest surface in the 3x3 (dilated edges), from its depth
//      reprojected with last frame's unjittered view-projection (camera motion);
//   3. the history sampled there (Catmull-Rom), rejected where it shows another surface (its
//      stored inverse depth is not the reprojected one: disocclusion, moving objects) or lies
//      off screen;
//   4. the history clipped toward the neighbourhood's mean, into its box of mean +- sigma in
//      YCoCg (variance clipping), so that what the history shows and this frame does not
//      cannot persist;
//   5. an exponential blend (at least currentWeight of this frame).
// Filtering and blending happen in the compressed space of taa.glsl. The output's alpha is the
// inverse linear depth of the closest surface in the pixel's 3x3 (0: sky), the next frame's
// disocclusion test.
#include "common/bindless.glsl"
#include "taa/taa.glsl"
#include "taa/taa_types.h"

layout(local_size_x = TAA_GROUP_X, local_size_y = TAA_GROUP_Y) in;
layout(push_constant, scalar) uniform Push {
    TaaResolvePush pc;
};

shared uint gRejected, gClipped;
// The group's pixels and a one-pixel border: this frame's compressed colour and its depth,
// fetched once each instead of nine times (every pixel reads its 3x3).
const uint kTileX = TAA_GROUP_X + 2u, kTileY = TAA_GROUP_Y + 2u;
shared vec3 gTileColour[kTileX * kTileY];
shared float gTileDepth[kTileX * kTileY];

// Relative difference of inverse depths above which the history shows another surface.
const float kDepthTolerance = 0.04;
// The colour box: mean +- kClipSigma standard deviations.
const float kClipSigma = 1.0;

vec3 currentSample(ivec2 q, float exposure) {
    q = clamp(q, ivec2(0), ivec2(pc.width - 1u, pc.height - 1u));
    vec3 c = max(fetchTextureUniform(pc.hdrSlot, q, 0).rgb, vec3(0.0)) * exposure;
    return taaCompress(c);
}

// The history's colour at pixel position `pos` (pixel centres at +0.5), Catmull-Rom from five
// bilinear taps (the four corner taps' weights are left out and the rest renormalised).
vec3 historyCatmullRom(vec2 pos) {
    vec2 size = vec2(pc.width, pc.height);
    vec2 t1 = floor(pos - 0.5) + 0.5;
    vec2 f = pos - t1;
    vec2 w0 = f * (-0.5 + f * (1.0 - 0.5 * f));
    vec2 w1 = 1.0 + f * f * (-2.5 + 1.5 * f);
    vec2 w2 = f * (0.5 + f * (2.0 - 1.5 * f));
    vec2 w3 = f * f * (-0.5 + 0.5 * f);
    vec2 w12 = w1 + w2;
    vec2 p0 = (t1 - 1.0) / size, p3 = (t1 + 2.0) / size, p12 = (t1 + w2 / w12) / size;
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    vec2 uv[5] = vec2[5](vec2(p12.x, p0.y), vec2(p0.x, p12.y), p12, vec2(p3.x, p12.y),
                         vec2(p12.x, p3.y));
    float w[5] = float[5](w12.x * w0.y, w0.x * w12.y, w12.x * w12.y, w3.x * w12.y, w12.x * w3.y);
    for (int i = 0; i < 5; ++i) {
        sum += sampleTextureLod(pc.historySlot, SAMPLER_LINEAR_CLAMP, uv[i], 0.0).rgb * w[i];
        weight += w[i];
    }
    return max(sum / weight, vec3(0.0));
}

// Whether the history shows the surface expected at unjittered position `pos`: the inverse
// depths it stored were sampled at last frame's jittered positions. Inverse depth is linear on
// screen over a plane, so its bilinear interpolation there matches on any slope; at an edge the
// nearest texel may match instead. (Accepting any texel of the 3x3 around it lets colour leak
// across edges over the frames: -1.2 dB against SSAA on a decoupled orbit.)
bool historyShowsSurface(vec2 pos, float expectedInvDepth) {
    vec2 at = pos - pc.prevJitter - 0.5; // in texel units, texel centres at integers
    ivec2 base = ivec2(floor(at));
    vec2 t = at - vec2(base);
    ivec2 last = ivec2(pc.width - 1u, pc.height - 1u);
    float stored[4];
    for (int i = 0; i < 4; ++i)
        stored[i] = fetchTextureUniform(pc.historySlot, clamp(base + ivec2(i & 1, i >> 1), ivec2(0), last), 0).a;
    float bilinear = mix(mix(stored[0], stored[1], t.x), mix(stored[2], stored[3], t.x), t.y);
    if (abs(bilinear - expectedInvDepth) <= kDepthTolerance * expectedInvDepth + 1e-6) return true;
    float nearest = stored[(t.x >= 0.5 ? 1 : 0) + (t.y >= 0.5 ? 2 : 0)];
    return abs(nearest - expectedInvDepth) <= kDepthTolerance * max(nearest, expectedInvDepth) + 1e-6;
}

// The history clipped along the line to the box centre until it lies in the box (YCoCg).
vec3 clipToBox(vec3 history, vec3 center, vec3 extent, out bool clipped) {
    vec3 d = history - center;
    vec3 units = abs(d) / max(extent, vec3(1e-5));
    float m = max(units.x, max(units.y, units.z));
    clipped = m > 1.0;
    return clipped ? center + d / m : history;
}

// Fills the tile: the group's pixels and their border, clamped to the image.
void loadTile(float exposure) {
    ivec2 origin = ivec2(gl_WorkGroupID.xy * uvec2(TAA_GROUP_X, TAA_GROUP_Y)) - 1;
    ivec2 last = ivec2(pc.width - 1u, pc.height - 1u);
    for (uint i = gl_LocalInvocationIndex; i < kTileX * kTileY; i += TAA_GROUP_X * TAA_GROUP_Y) {
        ivec2 q = clamp(origin + ivec2(i % kTileX, i / kTileX), ivec2(0), last);
        gTileColour[i] = currentSample(q, exposure);
        gTileDepth[i] = fetchTextureUniform(pc.depthSlot, q, 0).r;
    }
}

void main() {
    bool lead = gl_LocalInvocationIndex == 0u;
    if (lead) gRejected = gClipped = 0u;
    // Only the fields used: copying the whole frame block per invocation is costly on some
    // compilers.
    FrameConstantsRef frame = FrameConstantsRef(pc.frame);
    const float exposure = frame.f.exposure;
    loadTile(exposure);
    barrier();
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    bool inside = p.x < int(pc.width) && p.y < int(pc.height);
    if (inside) {
        vec2 size = vec2(pc.width, pc.height);
        ivec2 local = ivec2(gl_LocalInvocationID.xy) + 1; // in the tile
        // 1. Reconstruction and the neighbourhood's moments; 2. the closest depth.
        vec3 sum = vec3(0.0), m1 = vec3(0.0), m2 = vec3(0.0);
        float weight = 0.0, closest = -1.0;
        ivec2 closestAt = p;
        for (int y = -1; y <= 1; ++y) {
            for (int x = -1; x <= 1; ++x) {
                ivec2 q = p + ivec2(x, y);
                uint t = uint(local.y + y) * kTileX + uint(local.x + x);
                vec3 c = gTileColour[t];
                vec2 d = vec2(x, y) + pc.jitter;
                float w = exp(-2.29 * dot(d, d));
                sum += c * w;
                weight += w;
                vec3 ycocg = rgbToYCoCg(c);
                m1 += ycocg;
                m2 += ycocg * ycocg;
                ivec2 qc = clamp(q, ivec2(0), ivec2(size) - 1);
                float depth = gTileDepth[t];
                if (depth > closest) closest = depth, closestAt = qc;
            }
        }
        vec3 current = sum / weight;
        vec3 mean = m1 / 9.0;
        vec3 sigma = sqrt(max(m2 / 9.0 - mean * mean, vec3(0.0)));

        // 2. Where the closest surface was last frame (homogeneous: the sky is a direction).
        vec2 closestNdc = (vec2(closestAt) + 0.5) / size * 2.0 - 1.0;
        vec4 closestWorld = frame.f.invViewProj * vec4(closestNdc, closest, 1.0);
        vec4 prevClip = pc.prevViewProj * closestWorld;
        vec2 prevPos = (prevClip.xy / prevClip.w * 0.5 + 0.5) * size;
        vec2 nowPos = vec2(closestAt) + 0.5 + pc.jitter;
        vec2 historyPos = vec2(p) + 0.5 + (prevPos - nowPos);
        float expectedInvDepth = closest > 0.0 ? closestWorld.w / prevClip.w : 0.0;
        // The closest surface's inverse depth now, for the next frame's test (the w row of
        // viewProj has no jitter in it). Dilated as the expected one is: at an edge both are the
        // front surface's, whichever side this frame's jitter sampled.
        float invDepth = closest > 0.0 ? closestWorld.w / (frame.f.viewProj * closestWorld).w : 0.0;

        // 3. Rejection; 4. clipping; 5. the blend.
        bool valid = (pc.flags & TAA_HISTORY_VALID) != 0u && prevClip.w > 0.0 &&
                     all(greaterThanEqual(historyPos, vec2(0.0))) &&
                     all(lessThanEqual(historyPos, size)) &&
                     historyShowsSurface(historyPos, expectedInvDepth);
        vec3 result = current;
        bool clipped = false;
        if (valid) {
            vec3 history = taaCompress(historyCatmullRom(historyPos) * exposure);
            vec3 h = yCoCgToRgb(clipToBox(rgbToYCoCg(history), mean, kClipSigma * sigma, clipped));
            result = mix(h, current, pc.currentWeight);
        }
        vec3 hdr = taaExpand(clamp(result, vec3(0.0), vec3(0.999))) / max(exposure, 1e-20);
        imageStore(gImagesRgba16f[pc.outputSlot], p, vec4(hdr, invDepth));
        if (!valid) atomicAdd(gRejected, 1u);
        if (clipped) atomicAdd(gClipped, 1u);
    }
    barrier();
    if (lead) {
        UintBuffer counters = UintBuffer(pc.counters);
        if (gRejected > 0u) atomicAdd(counters.v[TAA_COUNTER_REJECTED], gRejected);
        if (gClipped > 0u) atomicAdd(counters.v[TAA_COUNTER_CLIPPED], gClipped);
    }
}
