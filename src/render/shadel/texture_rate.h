#pragma once
// Texture-limited shading rate: the material shading rate (material_rate.h) for textured
// materials. A textured rough material's surface shows its textures times smooth lighting, so
// where the view magnifies the textures (a close-up, a low-resolution texture: assimp's
// BoxTextured, 211x211 texels on a face, was shaded 2.41 shadels per covered pixel at 1280x720)
// shading it much finer than its texels adds nothing. `textureLod` is the finest whole level
// whose shadels lie at most half a texel of the material's densest texture apart
// (GpuShadelObject::textureLod). shadelLevels (shaders/shadel/shadel.glsl) then:
//   - coarsens a sample by the rate's bias, but never past the level before textureLod (a
//     quarter texel): at half a texel the texture's sharp edges, filtered twice (the texture
//     sample, then the shadels' bilinear reconstruction), softened visibly;
//   - reads one level instead of blending two (the band closes with the bias) where both levels
//     it could blend hold the textures at half a texel or finer (lod < textureLod).
// Where the textures are minified nothing changes.
//
// Against 4x4 SSAA forward (docs/shading_rate), shadels per covered pixel and PSNR, before ->
// after: BoxTextured 1280x720 2.410 -> 1.631, 44.543 -> 44.532 dB; 1920x1080 2.309 -> 1.537,
// 46.435 -> 46.425 dB; boxTexcoords 1280x720 2.408 -> 1.046, 45.499 -> 45.471 dB. Tried:
// coarsening to half a texel (one level further) gave BoxTextured 1.219 at 44.510 dB but cost
// TextureTransformTest 3.6 dB at 1920x1080 (44.614 -> 41.012), its letters' edges softer.
//
// Two measurements give textureLod, both taken once at load:
//   - per mesh, how many material-UV units one MIP-0 shadel spans (uvPerShadelLog2), from the
//     triangles' UV and shadel-UV areas: the 95th percentile by surface, so a mesh whose mapping
//     is denser in places is taken at its dense end;
//   - per material, the texels per UV unit of its densest texture (with KHR_texture_transform's
//     scale), per UV set (a slot reads TEXCOORD_0 or TEXCOORD_1; each set is measured per mesh,
//     and the denser of the two products sets the level), and a lower bound of the roughness its
//     metallic-roughness texture gives (the 2nd percentile of G), so a rough factor over a glossy
//     texture keeps the full rate.
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "common/shared_types.h"

namespace shadel {

struct Scene;

// log2 of the material-UV units one MIP-0 shadel spans (linear), over the mesh's triangles: the
// 95th percentile by shadel area of each triangle's sqrt(UV area / shadel area). -infinity when
// the UVs do not vary (a constant texture lookup: no texture detail at all).
float uvPerShadelLog2(std::span<const glm::vec2> materialUv, std::span<const glm::vec2> shadelUv,
                      std::span<const uint32_t> indices, glm::uvec2 mip0Size);

// What a material's textures allow, per Scene::materials entry.
struct MaterialTexels {
    bool known = false;          // false: the rate keeps the full rate (unknown texture content)
    float texelsPerUvLog2 = 0;   // log2 of its densest texture's texels per UV unit (linear)
    float texelsPerUv1Log2 = 0;  // ... of the textures on the second UV set (-inf: none)
    float roughnessScale = 1.0f; // lower bound of the metallic-roughness texture's G (0..1)
};
std::vector<MaterialTexels> materialTexels(const Scene& scene);

// GpuShadelObject::textureLod (in MIP-0 shadel units, as shadelLevels' lod): the finest whole
// level whose shadels lie at most 1 / shadelsPerTexel texels apart; the rate coarsens a sample
// no further than the level before it. A MIP-0 shadel spans 2^(uvPerShadelLog2 +
// texelsPerUvLog2) texels, a level-L shadel 2^L times that. Clamped to
// +-SHADEL_TEXTURE_LOD_NONE (shared_types.h): +NONE when the textures have no detail.
float textureLod(float uvPerShadelLog2, float texelsPerUvLog2, float shadelsPerTexel);

// Whether two materials sample the same textures the same way (slots, transforms, clamping):
// an edited material whose textures changed has no MaterialTexels (the full rate).
bool sameTextures(const gpu::GpuMaterial& a, const gpu::GpuMaterial& b);

} // namespace shadel
