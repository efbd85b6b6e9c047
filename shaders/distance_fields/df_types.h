// Mesh distance field layouts shared by C++ (render/distance_fields) and GLSL.
#ifndef SHADEL_DF_TYPES_H
#define SHADEL_DF_TYPES_H

#ifdef __cplusplus
#include "common/shared_types.h"
namespace shadel::gpu {
using glm::uvec3;
#endif

// Where a mesh's field sits in the atlas (voxels), and how its voxels map to object space.
struct GpuDistanceFieldMesh {
    uvec3 atlasOrigin;
    uint valid; // 0: the mesh has no field (not built, or the atlas had no room)
    uvec3 resolution;
    float voxelSize; // object-space metres
    vec3 origin;     // object-space centre of voxel (0, 0, 0)
    float pad;
};

// One shadow- and occlusion-casting instance.
struct GpuDistanceFieldInstance {
    mat4 worldToObject;
    vec3 worldMin;
    float scale; // world metres per object metre (uniform part of the transform)
    vec3 worldMax;
    uint mesh;
};

struct DistanceFieldFrame {
    uint64_t atlas;     // float[atlasSize.x * atlasSize.y * atlasSize.z], x fastest
    uint64_t meshes;    // GpuDistanceFieldMesh[]
    uint64_t instances; // GpuDistanceFieldInstance[]
    uint instanceCount;
    uint pad;
    uvec3 atlasSize;
    float softness; // k of the soft shadow: min(k d / t) along the ray
};

#ifdef __cplusplus
} // namespace shadel::gpu
#endif
#endif
