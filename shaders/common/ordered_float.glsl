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
#endif
