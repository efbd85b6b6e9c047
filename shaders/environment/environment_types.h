// The environment (image-based lighting) as shaders read it: shared by C++
// (render/environment/environment_state.h) and GLSL (shaders/environment/environment.glsl),
// scalar block layout on both sides, following common/shared_types.h's conventions.
#ifndef SHADEL_ENVIRONMENT_TYPES_H
#define SHADEL_ENVIRONMENT_TYPES_H

#ifdef __cplusplus
#include "common/shared_types.h"
namespace shadel::gpu {
#endif

// GpuEnvironment::flags
#define ENVIRONMENT_FLAG_NONE 1u     // no environment: lighting and background read 0
#define ENVIRONMENT_FLAG_SUN_DISC 2u // the background draws the sun's disc

// Every map is equirectangular in the convention of render/environment/equirect.h (row 0 looks
// up, the middle column along +Z), sampled bilinearly with u wrapping and v kept inside the
// first and last rows' texel centres.
struct GpuEnvironment {
    uint specularSlot;    // radiance, GGX-prefiltered: MIP l for perceptual roughness
                          // l / (specularLevels - 1), level 0 unfiltered
    uint irradianceSlot;  // irradiance / pi (the Lambert radiance for albedo 1)
    uint backgroundSlot;  // what the camera sees behind the scene (without the sun's disc)
    uint brdfSlot;        // (n.v, perceptual roughness): GGX scale, GGX bias, sheen albedo
    uint specularLevels;  // MIP count of the specular map
    uint flags;           // ENVIRONMENT_FLAG_*
    float intensity;      // multiplies every radiance (not the BRDF table)
    float rotationCos;    // world to environment: the rotation about +Y by the environment
    float rotationSin;    // rotation angle (x' = c x + s z, z' = -s x + c z)
    float sunCosRadius;   // cosine of the sun disc's angular radius
    float specularHeight; // texel rows of specular level 0 (level l: max(height >> l, 1))
    float irradianceHeight;
    vec3 sunDirection;    // the way sunlight travels, in the environment's frame
    float backgroundHeight;
    vec3 sunRadiance;     // radiance of the disc (0 without one)
    float brdfSize;       // texels per side of the BRDF table
};

#ifdef __cplusplus
} // namespace shadel::gpu
#endif
#endif
