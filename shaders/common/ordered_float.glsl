// Order-preserving float <-> uint (for atomicMin/Max on signed floats in shared memory).
#ifndef SHADEL_ORDERED_FLOAT_GLSL
#define SHADEL_ORDERED_FLOAT_GLSL
uint orderedFloatBits(float x) {
    uint b = floatBitsToUint(x);
    return (b & 0x80000000u) != 0u ? ~b : b | 0x80000000u;
}
float orderedBitsFloat(uint b) {
    return uintBitsToFloat((b & 0x80000000u) != 0u ? b & 0x7FFFFFFFu : ~b);
}
uvec3 orderedFloatBits(vec3 v) {
    return uvec3(orderedFloatBits(v.x), orderedFloatBits(v.y), orderedFloatBits(v.z));
}
vec3 orderedBitsFloat(uvec3 b) {
    return vec3(orderedBitsFloat(b.x), orderedBitsFloat(b.y), orderedBitsFloat(b.z));
}
#endif
