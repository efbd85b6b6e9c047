#pragma once
// glTF animation evaluated at one time (`--time SECONDS`): every channel of every animation sets
// its node's translation, rotation, scale or morph weights to the sampler's value at that time
// (STEP, LINEAR with slerp for rotations, CUBICSPLINE; times before the first key or after the
// last clamp to it). Applied to the tinygltf model before conversion, so the importer then
// builds the posed scene (node TRS, morph targets; the importer skins meshes by their posed
// joints when a time is given).
#include <functional>
#include <string>

#include <tiny_gltf.h>

namespace shadel {

// Throws InputError "<input>: animation A channel C: reason" for malformed animation data.
void poseAnimations(tinygltf::Model& model, double time, const std::string& input,
                    const std::function<void(const std::string&)>& warn);

} // namespace shadel
