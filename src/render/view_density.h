#pragma once
// View-driven shadel density: each mesh gets the density the cameras of this run can
// need, instead of one shadels-per-metre for the whole scene.
//
// For an instance seen at nearest distance d by a camera with focal length f pixels, a MIP-0
// shadel covers at most one pixel there when the world density is f / d shadels per metre (a
// pixel at distance d spans about d / f metres; farther parts of the instance read coarser MIPs).
// In object space that is times the instance's largest scale; a mesh takes the maximum over its
// instances, times a small safety factor (pixels off the view centre span less, charts vary in
// density), rounded *up* to a power of 2^(1/4) so nearby cameras bake the same (cache hits).
// A mesh no view sees gets a token density (its rect stays minimal).
//
// Chunks: a mesh much larger than the distance it is seen from is split on a grid (see
// mesh_split.h) into chunks no larger than `chunkPerDistance` times their own nearest distance,
// so density follows distance chunk by chunk and every chunk's atlas stays well below the
// baker's maxResolution. Chunks that would be small on the sheet anyway are not split further.
//
// Budget: if all meshes together would need more than `budget` MIP-0 shadels, every density is
// scaled down by the same factor (reported).
#include <string>
#include <vector>

#include "render/view_distance.h"
#include "scene/scene.h"

namespace shadel {

struct ViewDensityOptions {
    float safety = 1.0f;           // density over f / d
    float stepsPerOctave = 4;      // quantisation of densities
    double budget = 64e6;          // MIP-0 shadels for the whole scene
    bool chunks = true;            // split large meshes
    float chunkPerDistance = 1.0f; // chunk extent <= this times its nearest distance
    float minChunkShadels = 512;   // ...unless its MIP-0 side would be below this anyway
    uint32_t maxCellsPerAxis = 64; // finest grid: mesh extent / this, rounded up to 2^k
};

struct ViewDensity {
    Scene scene;                    // the scene to render (chunks replace split meshes)
    std::vector<float> meshDensity; // per scene.meshes[i]: shadels per object-space unit
    double budgetScale = 1;         // < 1 when the budget lowered every density
    double mip0Shadels = 0;         // estimated MIP-0 shadels at the chosen densities
    uint32_t meshesSplit = 0, chunksMade = 0;
    uint32_t meshesUnseen = 0;                      // meshes no view sees (token density)
    float minDensityWorld = 0, maxDensityWorld = 0; // over seen meshes, per metre of world
};

ViewDensity viewDrivenDensity(const Scene& scene, const RunViews& views,
                              const ViewDensityOptions& options);

} // namespace shadel
