#version 460
// --taa-sharpen: an unsharp mask over the resolved colour (the centre pushed away from the mean
// of its four neighbours by `amount`), in the compressed space of taa.glsl. It writes the
// displayed image only: the history stays unsharpened, so sharpening does not accumulate.
#include "common/bindless.glsl"
#include "taa/taa.glsl"
#include "taa/taa_types.h"

layout(local_size_x = TAA_GROUP_X, local_size_y = TAA_GROUP_Y) in;
layout(push_constant, scalar) uniform Push {
    TaaSharpenPush pc;
};

vec3 resolvedAt(ivec2 q, float exposure) {
    q = clamp(q, ivec2(0), ivec2(pc.width - 1u, pc.height - 1u));
    return taaCompress(fetchTextureUniform(pc.inputSlot, q, 0).rgb * exposure);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) return;
    float exposure = max(FrameConstantsRef(pc.frame).f.exposure, 1e-20);
    vec3 c = resolvedAt(p, exposure);
    vec3 around = resolvedAt(p + ivec2(1, 0), exposure) + resolvedAt(p - ivec2(1, 0), exposure) +
                  resolvedAt(p + ivec2(0, 1), exposure) + resolvedAt(p - ivec2(0, 1), exposure);
    vec3 sharpened = clamp(c + pc.amount * (c - 0.25 * around), vec3(0.0), vec3(0.999));
    imageStore(gImagesRgba16f[pc.outputSlot], p, vec4(taaExpand(sharpened) / exposure, 1.0));
}
