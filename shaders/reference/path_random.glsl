// Random numbers of the reference path tracer: one PCG stream per path, started from a hash of
// the pixel, the path's index over the whole accumulation and --seed. Every path of every frame
// draws from a stream of its own, so frames add independent samples; the same seed replays the
// same streams (the same image).
#ifndef SHADEL_PATH_RANDOM_GLSL
#define SHADEL_PATH_RANDOM_GLSL
#include "raytracing/rt_effects.glsl" // rtHash

uint gPathRandom;

void pathRandomStart(uvec2 pixel, uint pathIndex, uint seed) {
    gPathRandom = rtHash(pixel.x ^ rtHash(pixel.y ^ rtHash(pathIndex ^ rtHash(seed ^ 0x5eed5eedu))));
}

// Uniform in [0, 1) (24 bits): PCG-RXS-M-XS on 32 bits.
float pathRandom() {
    gPathRandom = gPathRandom * 747796405u + 2891336453u;
    uint word = ((gPathRandom >> ((gPathRandom >> 28u) + 4u)) ^ gPathRandom) * 277803737u;
    word = (word >> 22u) ^ word;
    return float(word >> 8u) * (1.0 / 16777216.0);
}

vec2 pathRandom2() {
    float x = pathRandom();
    return vec2(x, pathRandom());
}
#endif
