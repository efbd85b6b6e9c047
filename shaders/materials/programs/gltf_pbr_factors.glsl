// The glTF metal/rough model of the object's material factors (no textures), lit by the scene:
// the smallest program, the built-in glTF PBR program's result on untextured materials.
void main() {
    bool flip = (material.flags & MATERIAL_DOUBLE_SIDED) != 0u && !surface.frontFacing;
    vec3 color = lightSurface(material.baseColorFactor.rgb, material.metallicFactor,
                              material.roughnessFactor, flip ? -surface.normal : surface.normal);
    writeLayer(LAYER_RADIANCE, vec4(color + material.emissiveFactor, 1.0));
}
