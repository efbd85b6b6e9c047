// Two-band spherical harmonics (4 coefficients: Y00, then the x, y, z lobes) for the LPV.
#ifndef SHADEL_GI_SH_GLSL
#define SHADEL_GI_SH_GLSL

const float PI_GI = 3.14159265358979;
const float SH_Y0 = 0.282094792;   // 1 / (2 sqrt(pi))
const float SH_Y1 = 0.488602512;   // sqrt(3) / (2 sqrt(pi))
const float SH_COS_C0 = 0.886226925; // sqrt(pi) / 2: clamped cosine lobe, band 0
const float SH_COS_C1 = 1.023326708; // sqrt(pi / 3): clamped cosine lobe, band 1

// The basis evaluated in direction d (unit).
vec4 shBasis(vec3 d) {
    return vec4(SH_Y0, SH_Y1 * d.x, SH_Y1 * d.y, SH_Y1 * d.z);
}

// Projection of max(0, dot(d, w)): a Lambertian emitter or receiver facing d.
vec4 shCosineLobe(vec3 d) {
    return vec4(SH_COS_C0, SH_COS_C1 * d.x, SH_COS_C1 * d.y, SH_COS_C1 * d.z);
}
#endif
