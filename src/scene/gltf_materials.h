#pragma once
// glTF material extensions applied to the scene's Material at import (gltf_convert.cpp calls
// this; the shared material code in shaders/common/material.glsl evaluates the result, so the
// forward and decoupled paths agree):
//  KHR_texture_transform              uv transform per texture slot (offset, rotation, scale)
//                                     and its texCoord override (TEXCOORD_0 or TEXCOORD_1)
//  KHR_materials_emissive_strength    scales emissiveFactor
//  KHR_materials_unlit                output = base colour
//  KHR_materials_pbrSpecularGlossiness converted to metal/rough + specular (see .cpp)
//  KHR_materials_clearcoat            coat weight, roughness, normal (factors and textures)
//  KHR_materials_ior, _specular       dielectric F0/F90 (factors)
//  KHR_materials_sheen                sheen colour and roughness (factors)
// The JSON values were type- and range-checked by the importer's schema check.
#include <functional>
#include <string>

#include "scene/scene.h"

#include <tiny_gltf.h>

namespace shadel {

// Resolves a glTF texture index to a scene texture (kNoTexture when unusable); `slot` names it
// in warnings.
struct MaterialTextures {
    std::function<int32_t(int texture, bool srgb, const char* slot)> resolve;
    // The glTF texture's sampler (glTF's defaults filled in).
    std::function<TextureSampler(int texture)> sampler;
    // Converts a KHR_materials_pbrSpecularGlossiness specularGlossinessTexture into a
    // metallic-roughness texture (roughness = 1 - glossiness x factor); kNoTexture when unusable.
    std::function<int32_t(int texture, float glossinessFactor)> glossinessToRoughness;
    std::function<void(const std::string&)> warn;
};

// The sampler of glTF texture `texture` (a valid index): glTF's defaults for what it leaves out,
// repeat and the filters the Khronos Sample Viewer uses when none is given (linear magnification,
// trilinear minification); a texture without a sampler gets all of them.
TextureSampler gltfTextureSampler(const tinygltf::Model& model, int texture);

// Reads a texture info's KHR_texture_transform (identity when absent).
UvTransform uvTransformOf(const tinygltf::ExtensionMap& textureInfoExtensions);
// The UV set a texture info reads: KHR_texture_transform's texCoord when it gives one, else the
// texture info's own `texCoord`.
int texCoordOf(const tinygltf::ExtensionMap& textureInfoExtensions, int texCoord);

// Applies every supported extension of `gm` to `out` (whose core PBR fields are filled).
void applyMaterialExtensions(const tinygltf::Material& gm, int materialIndex, Material& out,
                             const MaterialTextures& textures);

} // namespace shadel
