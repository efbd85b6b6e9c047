// Stage 1: the terrain's material at this shadel, from its height: grass low, rock on the way
// up, snow on top. Base colour and roughness go to the material layer for the shade stage.
void main() {
    float h = terrainHeight(surface.position.xz) / heightScale; // 0 .. ~1.8
    vec3 albedo = mix(grass, rock, smoothstep(0.8, 1.05, h));
    albedo = mix(albedo, snow, smoothstep(1.3, 1.45, h));
    writeLayer(LAYER_MATERIAL, vec4(albedo, roughness));
}
